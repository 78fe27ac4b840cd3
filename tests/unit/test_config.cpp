// Scene files: unknown keys, wrong types and bad overrides are errors naming key and line.
#include <gtest/gtest.h>

#include "fsi/common/config.hpp"
#include "fsi/common/standalone.hpp"
#include "fsi/common/utf8.hpp"

namespace {

const char* kScene = R"(scene: t
solid:
  model: sdof
  mass: 2.0
  force: [1, 2]
  nested:
    depth: 3
)";

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const fsi::ConfigError& e) {
    return e.what();
  }
  return "";
}

TEST(Config, ReadsValuesWithDefaults) {
  auto scene = fsi::Scene::parse(kScene, "t.yaml");
  auto solid = scene.section("solid");
  EXPECT_EQ(solid.get<std::string>("model"), "sdof");
  EXPECT_DOUBLE_EQ(solid.get<double>("mass"), 2.0);
  EXPECT_DOUBLE_EQ(solid.get<double>("damping", 0.5), 0.5);
  EXPECT_EQ(solid.get<std::vector<double>>("force"), (std::vector<double>{1, 2}));
  EXPECT_EQ(solid.child("nested").get<int>("depth"), 3);
  EXPECT_NO_THROW(scene.check_all_used("solid"));
}

TEST(Config, UnknownKeyNamesKeyAndLine) {
  auto scene = fsi::Scene::parse(kScene, "t.yaml");
  auto solid = scene.section("solid");
  solid.get<std::string>("model");
  solid.get<double>("mass");
  solid.child("nested").get<int>("depth");
  const auto msg = error_of([&] { scene.check_all_used("solid"); });
  EXPECT_NE(msg.find("'solid.force'"), std::string::npos) << msg;
  EXPECT_NE(msg.find("t.yaml:5"), std::string::npos) << msg;
}

TEST(Config, ATabInTheIndentationIsNamedWithItsLine) {
  const std::string text = "solid:\n  model: sdof\n\tmass: 1\n";
  const auto msg = error_of([&] { (void)fsi::Scene::parse(text, "tab.yaml"); });
  EXPECT_NE(msg.find("not valid YAML"), std::string::npos) << msg;
  EXPECT_NE(msg.find("line 3 is indented with a tab"), std::string::npos) << msg;
  // Without a tab, no such hint.
  const auto other = error_of([&] { (void)fsi::Scene::parse("solid: [1, 2\n", "bracket.yaml"); });
  EXPECT_EQ(other.find("tab"), std::string::npos) << other;
}

TEST(Config, WrongTypeNamesKeyTypeAndLine) {
  auto scene = fsi::Scene::parse("solid:\n  mass: heavy\n", "t.yaml");
  const auto msg = error_of([&] { scene.section("solid").get<double>("mass"); });
  EXPECT_NE(msg.find("t.yaml:2"), std::string::npos) << msg;
  EXPECT_NE(msg.find("'solid.mass' must be a number"), std::string::npos) << msg;
  EXPECT_NE(msg.find("heavy"), std::string::npos) << msg;
}

TEST(Config, MissingRequiredKey) {
  auto scene = fsi::Scene::parse("solid:\n  model: sdof\n", "t.yaml");
  const auto msg = error_of([&] { scene.section("solid").get<double>("mass"); });
  EXPECT_NE(msg.find("'solid.mass' is required"), std::string::npos) << msg;
}

TEST(Config, NotFiniteIsRejected) {
  auto scene = fsi::Scene::parse("solid:\n  mass: .nan\n", "t.yaml");
  EXPECT_NE(error_of([&] { scene.section("solid").get<double>("mass"); }).find("finite"), std::string::npos);
}

TEST(Config, OverridesReplaceAndAdd) {
  auto scene = fsi::Scene::parse(kScene, "t.yaml", {"solid.mass=5", "solid.damping=0.25", "time.dt=0.1"});
  EXPECT_DOUBLE_EQ(scene.section("solid").get<double>("mass"), 5.0);
  EXPECT_DOUBLE_EQ(scene.section("solid").get<double>("damping"), 0.25);
  EXPECT_DOUBLE_EQ(scene.section("time").get<double>("dt"), 0.1);
  EXPECT_TRUE(scene.has("time.dt"));
  EXPECT_FALSE(scene.has("time.end"));
}

TEST(Config, OverrideOfUnknownKeyIsReportedAsFromSet) {
  auto scene = fsi::Scene::parse("solid:\n  mass: 1\n", "t.yaml", {"solid.masss=2"});
  scene.section("solid").get<double>("mass");
  const auto msg = error_of([&] { scene.check_all_used(); });
  EXPECT_NE(msg.find("'solid.masss'"), std::string::npos) << msg;
  EXPECT_NE(msg.find("--set"), std::string::npos) << msg;
}

TEST(Config, MalformedOverrideAndYaml) {
  EXPECT_NE(error_of([] { fsi::Scene::parse("a: 1\n", "t.yaml", {"novalue"}); }).find("dotted.key=value"),
            std::string::npos);
  const auto msg = error_of([] { fsi::Scene::parse("a: [1, 2\nb: 3\n", "bad.yaml"); });
  EXPECT_NE(msg.find("bad.yaml:"), std::string::npos) << msg;
  EXPECT_NE(error_of([] { fsi::Scene::load("/nonexistent/scene.yaml"); }).find("cannot open"), std::string::npos);
}

TEST(Config, HasDoesNotModifyTheTree) {
  auto scene = fsi::Scene::parse(kScene, "t.yaml");
  EXPECT_TRUE(scene.has("solid.nested.depth"));
  EXPECT_FALSE(scene.has("solid.nope"));
  EXPECT_EQ(scene.section("solid").get<std::string>("model"), "sdof");
  EXPECT_DOUBLE_EQ(scene.section("solid").get<double>("mass"), 2.0);
}

}  // namespace

namespace {

TEST(Config, DuplicateKeyNamesBothLines) {
  const std::string text = "scene: t\nsolid:\n  mass: 1\n  damping: 0\n  mass: 2\n";
  const auto e = error_of([&] { fsi::Scene::parse(text, "d.yaml"); });
  EXPECT_EQ(e, "d.yaml:5:3: duplicate key 'solid.mass' (first at d.yaml:3:3)");
  EXPECT_NE(error_of([&] { fsi::Scene::parse("a: 1\na: 2\n", "top.yaml"); }).find("duplicate key 'a'"),
            std::string::npos);
}

TEST(Utf8, ValidTextUnchangedInvalidBytesEscaped) {
  EXPECT_EQ(fsi::valid_utf8("relaxation \xCE\xB2 = 0.5, \xE2\x82\xAC, \xF0\x9F\x98\x80"),
            "relaxation \xCE\xB2 = 0.5, \xE2\x82\xAC, \xF0\x9F\x98\x80");
  EXPECT_EQ(fsi::valid_utf8(std::string("entry 'a\xFF\x80"
                                        "b'")),
            "entry 'a\\xFF\\x80b'");
  EXPECT_EQ(fsi::valid_utf8("\xC0\xAF"), "\\xC0\\xAF");           // overlong '/'
  EXPECT_EQ(fsi::valid_utf8("\xED\xA0\x80"), "\\xED\\xA0\\x80");  // a surrogate
  EXPECT_EQ(fsi::valid_utf8("cut \xE2\x82"), "cut \\xE2\\x82");   // truncated at the end
  EXPECT_EQ(fsi::valid_utf8(std::string("nul\0ok", 6)), std::string("nul\0ok", 6));
}

TEST(Config, AliasInsideItsOwnAnchorIsRefusedNotAStackOverflow) {
  // yaml-cpp turns `&a [1, *a]` into a cycle; a walk over it used to recurse until the stack overflowed.
  const auto e = error_of([&] { fsi::Scene::parse("a1: &a1 [1, *a1]\ntime:\n  dt: 0.1\n", "c.yaml"); });
  EXPECT_NE(e.find("c.yaml: 'a1[1][1]"), std::string::npos) << e;
  EXPECT_NE(e.find("nested more than 64 levels deep; is an anchor (&) used inside itself?"), std::string::npos) << e;
}

TEST(Config, NotFiniteVectorSaysFinite) {
  auto scene = fsi::Scene::parse("fluid:\n  force: .nan\n", "f.yaml");
  const auto e = error_of([&] { fsi::read_vector2(scene.section("fluid"), "force"); });
  EXPECT_NE(e.find("'fluid.force' must be a finite number"), std::string::npos) << e;
  auto listed = fsi::Scene::parse("fluid:\n  force: [1, .inf]\n", "f.yaml");
  EXPECT_NE(error_of([&] { fsi::read_vector2(listed.section("fluid"), "force"); }).find("finite"), std::string::npos);
}

TEST(Config, EndMustBeAWholeNumberOfSteps) {
  auto scene = fsi::Scene::parse("time: {dt: 0.02, end: 0.05}\n", "e.yaml");
  const auto e = error_of([&] { fsi::read_time(scene); });
  EXPECT_NE(e.find("'time.end' (0.05) must be a whole number of time steps dt = 0.02: end / dt = 2.5; use 0.04 (2 "
                   "steps) or 0.06 (3 steps)"),
            std::string::npos)
      << e;
  auto ok = fsi::Scene::parse("time: {dt: 0.0025, end: 4.5}\n", "e.yaml");
  EXPECT_EQ(fsi::read_time(ok).steps, 1800);
}

}  // namespace

// A scene is UTF-8 text without NUL bytes: anything else is refused at its place, before any
// key is read (a Latin-1 comment once passed `fsi check` and failed on the wire; a NUL after a
// value turned the number into a string).
TEST(SceneBytes, Latin1ByteIsRefusedWithItsLineAndColumn) {
  try {
    (void)fsi::Scene::parse("time: {dt: 0.1, end: 1.0}\n# caf\xE9 au lait\n", "s.yaml");
    FAIL() << "a Latin-1 byte was accepted";
  } catch (const fsi::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("s.yaml:2:6: byte 0xE9 is not UTF-8"), std::string::npos) << e.what();
  }
}

TEST(SceneBytes, NulByteIsRefusedWithItsPlace) {
  const std::string text = std::string("solid:\n  mass: 1.0") + '\0' + "x\n";
  try {
    (void)fsi::Scene::parse(text, "s.yaml");
    FAIL() << "a NUL byte was accepted";
  } catch (const fsi::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("s.yaml:2:12: a NUL byte"), std::string::npos) << e.what();
  }
}

TEST(SceneBytes, Utf16IsRefusedAsUtf16) {
  const std::string text("\xFF\xFEt\0i\0m\0e\0", 10);
  EXPECT_THROW((void)fsi::Scene::parse(text, "s.yaml"), fsi::ConfigError);
  try {
    (void)fsi::Scene::parse(text, "s.yaml");
  } catch (const fsi::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("UTF-16"), std::string::npos) << e.what();
  }
}

TEST(SceneBytes, ValidUtf8IsAccepted) {
  EXPECT_NO_THROW((void)fsi::Scene::parse("description: \"caf\xC3\xA9, \xCE\xB3_N1 = 100\"\n", "s.yaml"));
}
