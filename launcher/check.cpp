#include "check.hpp"

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include <iostream>
#include <nlohmann/json.hpp>

#include "fsi/common/config.hpp"
#include "fsi/common/scene_schema.hpp"

namespace fsi::launcher {
namespace {

void print(const std::vector<schema::Problem>& problems) {
  for (const auto& p : problems) std::cerr << p.text() << "\n";
}

}  // namespace

bool is_study_file(const std::string& file) {
  try {
    const YAML::Node root = YAML::LoadFile(file);
    return root.IsMap() && (root["study"] || root["vary"]);
  } catch (const YAML::Exception&) {
    return false;  // Scene::load says what is wrong with it
  }
}

namespace {
// One scene check with overrides (`placed`: with the place they were written), as JSON.
nlohmann::json check_json(const std::string& file, const std::vector<std::string>& overrides,
                          const std::vector<std::pair<std::string, std::string>>& placed,
                          const std::vector<std::string>& skip_sections = {}) {
  std::vector<std::string> all = overrides;
  schema::CheckOptions options;
  options.skip_sections = skip_sections;
  for (const auto& [assignment, where] : placed) {
    all.push_back(assignment);
    options.override_origins.push_back({assignment, where});
  }
  schema::CheckResult result;
  try {
    result = schema::check_scene(Scene::load(file, all), options);
  } catch (const ConfigError& e) {
    result.problems.push_back({"", e.what(), ""});
  }
  nlohmann::json out = {{"file", file}, {"keys_checked", result.keys_checked}, {"problems", nlohmann::json::array()}};
  for (const auto& p : result.problems)
    out["problems"].push_back({{"where", p.where}, {"message", p.message}, {"key", p.key}, {"text", p.text()}});
  return out;
}
}  // namespace

int check_file(const std::string& file, const std::vector<std::string>& overrides,
               const std::vector<std::pair<std::string, std::string>>& placed, bool json,
               const std::vector<std::string>& skip_sections) {
  const nlohmann::json result = check_json(file, overrides, placed, skip_sections);
  if (json) {
    std::cout << result.dump() << "\n";
    return result["problems"].empty() ? 0 : 1;
  }
  if (!result["problems"].empty()) {
    for (const auto& p : result["problems"]) std::cerr << p["text"].get<std::string>() << "\n";
    return 1;
  }
  std::string skipped;
  for (const auto& section : skip_sections) skipped += (skipped.empty() ? "" : ", ") + section;
  std::cout << fmt::format("OK: {} ({} keys checked{})\n", file, result["keys_checked"].get<int>(),
                           skipped.empty() ? "" : "; " + skipped + " left to the external solver");
  return 0;
}

int check_cases(const std::string& file, const std::vector<std::string>& overrides,
                const std::vector<std::pair<std::string, std::string>>& placed, std::istream& cases) {
  nlohmann::json list;
  try {
    list = nlohmann::json::parse(cases);
  } catch (const nlohmann::json::exception& e) {
    std::cerr << "fsi check --cases: not a JSON list of cases: " << e.what() << "\n";
    return 1;
  }
  nlohmann::json out = nlohmann::json::array();
  for (const auto& c : list) {
    auto with = placed;
    for (const auto& pair : c) with.push_back({pair.at(0).get<std::string>(), pair.at(1).get<std::string>()});
    out.push_back(check_json(file, overrides, with));
  }
  std::cout << out.dump() << "\n";
  return 0;
}

bool check_before_run(const std::string& scene_path, const std::vector<std::string>& overrides,
                      const std::vector<std::string>& skip_sections, std::string& problems) {
  try {
    schema::CheckOptions options;
    options.skip_sections = skip_sections;
    const auto result = schema::check_scene(Scene::load(scene_path, overrides), options);
    print(result.problems);
    for (const auto& p : result.problems) problems += (problems.empty() ? "" : "\n") + p.text();
    return result.ok();
  } catch (const ConfigError& e) {
    std::cerr << e.what() << "\n";
    problems = e.what();
    return false;
  }
}

}  // namespace fsi::launcher
