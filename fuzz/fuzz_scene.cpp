// libFuzzer target: bytes -> fsi::Scene::parse plus the reads a coupled run does on it
// (Scene::name, read_time, read_coupling, check_all_used, the top-level keys, and typed reads
// of solid/fluid keys as the models do: get<T>, read_vector2, child, list, get_path), and the
// scene schema's check (fsi check).
//
// Input: the scene text, optionally followed by '\0' and up to 8 '\0'-separated --set
// overrides ("solid.mass=2").
// Oracle: fsi::ConfigError (the documented error of config.hpp) is fine; any other
// exception escaping, a crash, UB or a hang is a finding.
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>
#include <vector>

#include "fsi/common/config.hpp"
#include "fsi/common/scene_schema.hpp"
#include "fsi/common/standalone.hpp"
#include "fsi/coupling/settings.hpp"
#include "fsi/models/fluid_factory.hpp"
#include "fsi/models/solid_factory.hpp"

namespace {

// The launcher's view: every section declared.
const bool kDeclared =
    (fsi::coupling::coupling_section(), fsi::models::solid_section(), fsi::models::fluid_section(), true);

template <class F>
void expect_config_errors_only(const char* what, F&& f) {
  try {
    f();
  } catch (const fsi::ConfigError&) {
  } catch (const std::exception& e) {
    std::fprintf(stderr, "fuzz_scene: %s threw a non-ConfigError std::exception: %s\n", what, e.what());
    std::abort();
  } catch (...) {
    std::fprintf(stderr, "fuzz_scene: %s threw a non-std::exception\n", what);
    std::abort();
  }
}

// Reads a model section the way the solid/fluid models do (a representative set of keys).
void read_model_section(const fsi::ConfigSection& s) {
  expect_config_errors_only("model", [&] { (void)s.get<std::string>("model"); });
  expect_config_errors_only("get<double>", [&] { (void)s.get<double>("mass", 1.0); });
  expect_config_errors_only("get<int>", [&] { (void)s.get<int>("load_steps", 1); });
  expect_config_errors_only("get<bool>", [&] { (void)s.get<bool>("stop_if_not_converged", true); });
  expect_config_errors_only("read_vector2", [&] { (void)fsi::read_vector2(s, "force"); });
  expect_config_errors_only("get<vector<string>>", [&] { (void)s.get<std::vector<std::string>>("interface", {}); });
  expect_config_errors_only("mesh", [&] {
    if (auto m = s.optional_child("mesh")) {
      (void)m->get<std::string>("type");
      (void)m->get<std::vector<int>>("elements", {});
      (void)m->get<std::vector<double>>("origin", {});
      if (m->has("file")) (void)m->get_path("file");
      (void)m->where("file");
    }
  });
  expect_config_errors_only("list", [&] {
    for (const auto& p : s.list("probes")) {
      (void)p.get<std::string>("name");
      (void)fsi::read_vector2(p, "point");
    }
  });
  expect_config_errors_only("keys", [&] {
    for (const auto& k : s.keys()) (void)s.where(k), (void)s.full_key(k), (void)s.node_is_scalar(k);
  });
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size > 16384) return 0;
  const std::string input(reinterpret_cast<const char*>(data), size);
  std::vector<std::string> parts;
  for (size_t at = 0;;) {
    const size_t nul = input.find('\0', at);
    parts.push_back(input.substr(at, nul == std::string::npos ? std::string::npos : nul - at));
    if (nul == std::string::npos || parts.size() > 8) break;
    at = nul + 1;
  }
  const std::string text = parts[0];
  const std::vector<std::string> overrides(parts.begin() + 1, parts.end());

  std::vector<fsi::Scene> scene;  // 0 or 1
  expect_config_errors_only("Scene::parse",
                            [&] { scene.push_back(fsi::Scene::parse(text, "fuzz/scene.yaml", overrides)); });
  if (scene.empty()) return 0;
  const fsi::Scene& s = scene[0];
  expect_config_errors_only("Scene::name", [&] { (void)s.name(); });
  expect_config_errors_only("Scene::has", [&] { (void)s.has("time.dt"), (void)s.has("coupling.iterations.max"); });
  expect_config_errors_only("read_time", [&] { (void)fsi::read_time(s); });
  expect_config_errors_only("read_coupling", [&] { (void)fsi::coupling::read_coupling(s.section("coupling")); });
  expect_config_errors_only("check_all_used(coupling)", [&] { s.check_all_used("coupling"); });
  expect_config_errors_only("check_all_used(time)", [&] { s.check_all_used("time"); });
  expect_config_errors_only("root keys", [&] {
    const auto root = s.root();
    for (const auto& key : root.keys()) (void)root.where(key);
  });
  for (const char* name : {"solid", "fluid"})
    expect_config_errors_only("section", [&] { read_model_section(s.section(name)); });
  expect_config_errors_only("check_all_used", [&] { s.check_all_used(); });
  expect_config_errors_only("schema::check_scene", [&] { (void)fsi::schema::check_scene(s); });
  expect_config_errors_only("schema::require_valid", [&] {
    fsi::schema::require_valid(s, {"time", "coupling", "solid", "fluid"});
  });
  return 0;
}
