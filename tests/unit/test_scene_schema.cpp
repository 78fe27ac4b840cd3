// The scene schema: suggestions, problems with their places, the servers' pre-check.
#include <gtest/gtest.h>

#include <filesystem>

#include "fsi/common/scene_reader.hpp"
#include "fsi/common/scene_schema.hpp"
#include "fsi/common/standalone.hpp"
#include "fsi/coupling/settings.hpp"
#include "fsi/models/fluid_factory.hpp"
#include "fsi/models/solid_factory.hpp"

namespace {

// The sections a program knows are the ones it declares (the launcher: all of them).
const bool kDeclared =
    (fsi::coupling::coupling_section(), fsi::models::solid_section(), fsi::models::fluid_section(), true);

std::vector<std::string> problems(const std::string& text, const std::vector<std::string>& overrides = {}) {
  std::vector<std::string> out;
  for (const auto& p : fsi::schema::check_scene(fsi::Scene::parse(text, "s.yaml", overrides)).problems)
    out.push_back(p.text());
  return out;
}

const std::string kScene =
    "time: {dt: 0.1, end: 1.0}\n"
    "coupling:\n"
    "  algorithm: 2\n"
    "  gamma_n1: 10\n"
    "  relaxation: 1.0\n"
    "  iterations: {max: 1}\n"
    "solid:\n"
    "  model: sdof\n"
    "  mass: 1.0\n"
    "fluid:\n"
    "  model: surrogate\n"
    "  force: [1.0, 0.0]\n";

TEST(SceneSchema, EditDistanceAndSuggestion) {
  EXPECT_EQ(fsi::schema::edit_distance("max_iteratons", "max_iterations"), 1u);
  EXPECT_EQ(fsi::schema::edit_distance("", "abc"), 3u);
  EXPECT_EQ(fsi::schema::closest("materal", {"mesh", "material", "density"}), "material");
  EXPECT_EQ(fsi::schema::closest("zzzzzz", {"mesh", "material"}), "");
  EXPECT_EQ(fsi::schema::closest("mesh", {"mesh"}), "");  // the word itself is no suggestion
}

TEST(SceneSchema, ValidSceneCountsItsKeys) {
  const auto r = fsi::schema::check_scene(fsi::Scene::parse(kScene, "s.yaml"));
  EXPECT_TRUE(r.ok());
  EXPECT_EQ(r.keys_checked, 15);  // 4 sections + 2 time + 4 coupling + 1 iterations + 2 solid + 2 fluid
}

TEST(SceneSchema, ProblemsNameKeyPlaceAndSuggestion) {
  std::string text = kScene;
  text.replace(text.find("  mass: 1.0"), 11, "  mass: heavy\n  stifness: 2");
  EXPECT_EQ(problems(text), (std::vector<std::string>{
                                "s.yaml:9:3: 'solid.mass' must be a number, got 'heavy'",
                                "s.yaml:10:3: unknown key 'solid.stifness' (did you mean 'stiffness'?)",
                            }));
  EXPECT_EQ(problems(kScene, {"fluid.added_mass=-1", "coupling.iqn.filter=0.5"}),
            (std::vector<std::string>{
                "s.yaml (--set coupling.iqn.filter=0.5): 'coupling.iqn' is only used when 'coupling.acceleration' "
                "is iqn-ils or iqn-imvj",
                "s.yaml (--set fluid.added_mass=-1): 'fluid.added_mass' must be >= 0, got '-1'",
            }));
  EXPECT_EQ(problems("time: {dt: 0.1, end: 1.0}\nsolid: {model: sdof, mass: 1}\nfluid: {model: surrogate}\n"),
            (std::vector<std::string>{"s.yaml: a scene without 'coupling' must have exactly one of 'solid' or "
                                      "'fluid'"}));
}

// Waveform iterations: every solver section (whatever its model) takes `substeps`, >= 1.
TEST(SceneSchema, SubstepsInEverySolverSectionAtLeastOne) {
  EXPECT_TRUE(problems(kScene, {"solid.substeps=4", "fluid.substeps=2"}).empty());
  EXPECT_EQ(problems(kScene, {"solid.substeps=0", "fluid.substeps=1.5"}),
            (std::vector<std::string>{
                "s.yaml (--set solid.substeps=0): 'solid.substeps' must be in [1, 1000], got '0'",
                "s.yaml (--set fluid.substeps=1.5): 'fluid.substeps' must be an integer, got '1.5'",
            }));
}

TEST(SceneSchema, IntegerListsNameTheBadEntryAndKeepTheirRange) {
  auto bad = [](const std::string& set) {
    std::vector<std::string> out;
    const auto scene = fsi::Scene::load(std::filesystem::path(FSI_SOURCE_DIR) / "configs/fsi1_p2p1.yaml", {set});
    for (const auto& p : fsi::schema::check_scene(scene).problems) out.push_back(p.text());
    return out;
  };
  const auto fractional = bad("fluid.remesh.at_steps=[3, 1.5]");
  ASSERT_EQ(fractional.size(), 1u);
  EXPECT_NE(fractional[0].find("'fluid.remesh.at_steps' must be a list of integers: entry 2 is '1.5'"),
            std::string::npos)
      << fractional[0];
  const auto negative = bad("fluid.remesh.at_steps=[-1]");
  ASSERT_EQ(negative.size(), 1u);
  EXPECT_NE(negative[0].find("'fluid.remesh.at_steps[0]' must be >= 1, got '-1'"), std::string::npos) << negative[0];
  EXPECT_TRUE(bad("fluid.remesh.at_steps=[2, 5]").empty());
}

TEST(SceneSchema, ServersValidateTheirSectionBeforeBuilding) {
  std::string text = kScene;
  text.replace(text.find("  mass: 1.0"), 11, "  mass: 1.0\n  dampng: 2");
  const auto scene = fsi::Scene::parse(text, "s.yaml");
  try {
    fsi::schema::require_valid(scene.section("solid"));
    FAIL() << "no error";
  } catch (const fsi::ConfigError& e) {
    EXPECT_STREQ(e.what(), "s.yaml:10:3: unknown key 'solid.dampng' (did you mean 'damping'?)");
  }
  // Other sections are not its business; a model the schema does not know is the factory's.
  EXPECT_NO_THROW(fsi::schema::require_valid(scene.section("fluid")));
  const auto other = fsi::Scene::parse("solid: {model: mine, anything: 1}\n", "o.yaml");
  EXPECT_NO_THROW(fsi::schema::require_valid(other.section("solid")));
}

TEST(SceneSchema, CheckAllUsedSuggestsAKeyTheReaderRead) {
  const auto scene = fsi::Scene::parse("solid:\n  mass: 1\n  dampng: 2\n", "t.yaml");
  const auto s = scene.section("solid");
  s.get<double>("mass");
  s.get<double>("damping", 0.0);
  try {
    scene.check_all_used("solid");
    FAIL() << "no error";
  } catch (const fsi::ConfigError& e) {
    EXPECT_STREQ(e.what(), "unknown key in scene: 'solid.dampng' at t.yaml:3:3 (did you mean 'damping'?)");
  }
}

// The schema and the readers agree: a scene with every key of a model passes the check, and
// the model reads every one of them (check_all_used, the readers' own test).
TEST(SceneSchema, EveryKeyOfTheSchemaIsReadByItsModel) {
  const std::string text =
      "time: {dt: 0.1, end: 0.2, output_every: 0, checkpoint_every: 0, checkpoint_keep: 2}\n"
      "coupling: {algorithm: 2, gamma_n1: 10, gamma_n2: -1, relaxation: 1.0, predictor: previous,\n"
      "           acceleration: iqn-ils, iqn: {reuse_steps: 4, filter: 0.01}, force_limit: 1.0e9,\n"
      "           mapping: rbf-wendland-c2, support_radius: 0.05,\n"
      "           iterations: {max: 3, tolerance: 1.0e-6, stop_if_not_converged: false, divergence_factor: 100}}\n"
      "solid: {model: sdof, mass: 1, damping: 0.1, stiffness: 2, interface_measure: 1, force: [1, 0],\n"
      "        initial_displacement: 0.1, initial_velocity: [0, 0.5]}\n"
      "fluid: {model: surrogate, force: 1.0, added_mass: 0.5, interface_measure: 1}\n"
      "fem:\n"
      "  model: fem\n"
      "  mesh: {type: rectangle, origin: [0, 0], size: [1, 0.1], elements: [4, 1]}\n"
      "  material: {law: neo_hookean, youngs_modulus: 1.0e6, poisson_ratio: 0.3}\n"
      "  density: 1000\n"
      "  gravity: [0, -1]\n"
      "  analysis: dynamic\n"
      "  time_scheme: bdf2\n"
      "  load_steps: 1\n"
      "  newton: {max_iterations: 10, residual_tolerance: 1.0e-8, increment_tolerance: 1.0e-12}\n"
      "  linear_solver: umfpack\n"
      "  clamp: left\n"
      "  interface: [top, right]\n"
      "  tractions: [{boundary: right, traction: [0, 1]}]\n"
      "  point_loads: [{point: [1, 0.1], force: [0, 1]}]\n"
      "  probes: [{name: A, point: [0.9, 0.05]}]\n"
      "  output_every: 1\n";
  // The fem solid in place of the sdof one (the schema checks `solid`).
  std::string fem = text.substr(text.find("fem:\n") + 5);
  std::string as_solid = text.substr(0, text.find("solid:")) + "solid:\n" + fem +
                         text.substr(text.find("fluid:"), text.find("fem:") - text.find("fluid:"));
  for (const auto& scene_text : {text.substr(0, text.find("fem:")), as_solid}) {
    const auto scene = fsi::Scene::parse(scene_text, "all.yaml");
    const auto r = fsi::schema::check_scene(scene);
    ASSERT_TRUE(r.ok()) << r.problems.front().text();
    const auto solid = scene.section("solid");
    auto model = fsi::make_model(fsi::SolidFactory(fsi::models::make_solid_model), solid, "solid");
    model->configure(solid, fsi::SolidSetup{0.1, 0.2, 0.0, {}});
    EXPECT_NO_THROW(scene.check_all_used("solid"));
  }
  const auto scene = fsi::Scene::parse(text.substr(0, text.find("fem:")), "all.yaml");
  const auto fluid = scene.section("fluid");
  auto model = fsi::make_model(fsi::FluidFactory(fsi::models::make_fluid_model), fluid, "fluid");
  model->configure(fluid, fsi::FluidSetup{0.1, 0.2, 10, -1, {}});
  EXPECT_NO_THROW(scene.check_all_used("fluid"));
  EXPECT_NO_THROW(fsi::read_time(scene));
  EXPECT_NO_THROW(scene.check_all_used("time"));
  (void)fsi::coupling::read_coupling(scene.section("coupling"));
  EXPECT_NO_THROW(scene.check_all_used("coupling"));
}

TEST(SceneSchema, ReferenceListsEveryModel) {
  const std::string md = fsi::schema::reference_markdown();
  for (const char* heading : {"## time", "## coupling", "### solid.model: sdof", "### solid.model: fem",
                              "### fluid.model: surrogate", "### fluid.model: fem"})
    EXPECT_NE(md.find(heading), std::string::npos) << heading;
  EXPECT_NE(md.find("| `fluid.nonlinear.max_iterations` | integer |  | `1` |"), std::string::npos);
}

}  // namespace

// The C++ settings' initialisers (used when code builds settings itself, as the tests do) are
// the scene's declared defaults: a scene that gives only the required keys reads the same.
TEST(DeclaredOnce, CouplingSettingsInitialisersAreTheDeclaredDefaults) {
  const auto scene = fsi::Scene::parse(
      "time: {dt: 0.1, end: 1.0}\ncoupling: {algorithm: 1, gamma_n1: 0, relaxation: 1, iterations: {max: 1}}\n",
      "s.yaml");
  const auto read = fsi::coupling::read_coupling(scene.section("coupling"));
  const fsi::coupling::CouplingSettings init;
  EXPECT_EQ(read.gamma_n2, init.gamma_n2);
  EXPECT_EQ(read.predictor, init.predictor);
  EXPECT_EQ(read.acceleration, init.acceleration);
  EXPECT_EQ(read.iqn_filter, init.iqn_filter);
  EXPECT_EQ(read.iqn_filter_type, init.iqn_filter_type);
  EXPECT_EQ(read.iqn_preconditioner, init.iqn_preconditioner);
  EXPECT_EQ(read.imvj_restart, init.imvj_restart);
  EXPECT_EQ(read.imvj_chunk_size, init.imvj_chunk_size);
  EXPECT_EQ(read.imvj_restart_reuse_steps, init.imvj_restart_reuse_steps);
  EXPECT_EQ(read.imvj_truncation, init.imvj_truncation);
  EXPECT_EQ(read.tolerance, init.tolerance);
  EXPECT_EQ(read.stop_if_not_converged, init.stop_if_not_converged);
  EXPECT_EQ(read.divergence_factor, init.divergence_factor);
  EXPECT_EQ(read.force_limit, init.force_limit);
  EXPECT_EQ(read.robin_mass, init.robin_mass);
  EXPECT_EQ(read.combine_all, init.combine_all);
}

// A reader that asks for a key its declaration lacks is a programming error, not a user's.
TEST(DeclaredOnce, ReadingAnUndeclaredKeyIsALogicError) {
  const auto scene = fsi::Scene::parse("time: {dt: 0.1, end: 1.0}\n", "s.yaml");
  const fsi::schema::Reader r(scene.section("time"), fsi::time_section());
  EXPECT_EQ(r.get<int>("checkpoint_keep"), 2);  // the declared default
  EXPECT_THROW((void)r.get<int>("checkpoint_kept"), std::logic_error);
  EXPECT_THROW((void)r.get_or<int>("checkpoint_keep", 3), std::logic_error);  // declared default: use get
}
