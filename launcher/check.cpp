#include "check.hpp"

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <filesystem>
#include <iostream>
#include <set>

#include "fsi/common/config.hpp"
#include "fsi/common/scene_schema.hpp"

namespace fs = std::filesystem;

namespace fsi::launcher {
namespace {

std::string at(const std::string& file, const YAML::Mark& mark) {
  if (mark.is_null()) return file;
  return fmt::format("{}:{}:{}", file, mark.line + 1, mark.column + 1);
}

std::string emit(const YAML::Node& value) {
  if (value.IsScalar()) return value.Scalar();
  if (!value || value.IsNull()) return "";
  YAML::Emitter out;
  out << YAML::Flow << value;
  return out.c_str();
}

void print(const std::vector<schema::Problem>& problems) {
  for (const auto& p : problems) std::cerr << p.text() << "\n";
}

// One key a study sets: its dotted name, the value, and where it is in the study file.
struct StudyKey {
  std::string key;
  YAML::Node value;
  std::string where;      // of the value (vary, zip) or of the key (fixed, derived)
  std::string key_where;  // of the key
};

struct Study {
  std::string file;         // the study file as given
  fs::path scene;           // resolved
  std::string scene_where;  // where `scene` is written
  std::vector<StudyKey> fixed, varied, derived;
};

// `fixed` nests like the study tool reads it: maps flatten to dotted keys.
void flatten(const YAML::Node& node, const std::string& prefix, const std::string& file, std::vector<StudyKey>& out) {
  for (const auto& kv : node) {
    const std::string key = prefix + kv.first.Scalar();
    if (kv.second.IsMap())
      flatten(kv.second, key + ".", file, out);
    else
      out.push_back({key, kv.second, at(file, kv.first.Mark()), at(file, kv.first.Mark())});
  }
}

// The values a `vary` / `zip` entry takes: a list, a scalar, or {linspace|geomspace|range: [a, b, n]}
// (its ends stand for the values between).
void varied_values(const std::string& key, const YAML::Node& values, const std::string& file,
                   const YAML::Mark& key_mark, std::vector<StudyKey>& out) {
  if (values.IsSequence()) {
    for (std::size_t i = 0; i < values.size(); ++i)
      out.push_back({key, values[i], at(file, values[i].Mark()), at(file, key_mark)});
  } else if (values.IsMap() && values.size() == 1) {
    const YAML::Node args = values.begin()->second;
    if (args.IsSequence() && args.size() >= 2)
      for (std::size_t i = 0; i < 2; ++i) out.push_back({key, args[i], at(file, args[i].Mark()), at(file, key_mark)});
  } else if (values.IsScalar()) {
    out.push_back({key, values, at(file, key_mark), at(file, key_mark)});
  }
}

void read_study(const fs::path& path, const std::string& shown, Study& study, int depth) {
  if (depth > 8) throw ConfigError(shown + ": 'extends' nests too deep");
  YAML::Node root;
  try {
    root = YAML::LoadFile(path.string());
  } catch (const YAML::ParserException& e) {
    throw ConfigError(at(shown, e.mark) + ": not valid YAML: " + e.msg);
  } catch (const YAML::BadFile&) {
    throw ConfigError("cannot open study file '" + shown + "'");
  }
  if (!root.IsMap()) throw ConfigError(shown + ": a study must be a YAML map");
  if (const auto parent = root["extends"]) {  // the parent first, this file's keys win
    const fs::path p = path.parent_path() / parent.as<std::string>("");
    read_study(p, (fs::path(shown).parent_path() / parent.as<std::string>("")).lexically_normal().string(), study,
               depth + 1);
  }
  if (const auto scene = root["scene"]) {
    const fs::path given(scene.as<std::string>(""));
    study.scene_where = at(shown, root["scene"].Mark());
    std::vector<fs::path> candidates{given};
    if (!given.is_absolute()) {
      candidates = {path.parent_path() / given, given};
#ifdef FSI_SOURCE_DIR
      candidates.push_back(fs::path(FSI_SOURCE_DIR) / given);
#endif
    }
    study.scene.clear();
    for (const auto& c : candidates)
      if (fs::is_regular_file(c)) {
        study.scene = c;
        break;
      }
    if (study.scene.empty())
      throw ConfigError(
          fmt::format("{}: scene '{}' not found (relative to the study, the working folder or the "
                      "source tree)",
                      study.scene_where, given.string()));
    // A path as the user sees it: relative to the working folder when below it.
    const auto relative = fs::relative(study.scene);
    if (!relative.empty() && relative.native().rfind("..", 0) != 0) study.scene = relative;
  }
  if (const auto fixed = root["fixed"]; fixed && fixed.IsMap()) {
    std::vector<StudyKey> keys;
    flatten(fixed, "", shown, keys);
    for (auto& k : keys) {  // a key of this file replaces the parent's
      study.fixed.erase(
          std::remove_if(study.fixed.begin(), study.fixed.end(), [&](const StudyKey& f) { return f.key == k.key; }),
          study.fixed.end());
      study.fixed.push_back(k);
    }
  }
  const auto vary = root["vary"];
  const auto zip = root["zip"];
  if (vary || zip) study.varied.clear();
  if (vary && vary.IsMap())
    for (const auto& kv : vary) varied_values(kv.first.Scalar(), kv.second, shown, kv.first.Mark(), study.varied);
  if (zip && zip.IsSequence())
    for (std::size_t i = 0; i < zip.size(); ++i)
      if (zip[i].IsMap())
        for (const auto& kv : zip[i]) varied_values(kv.first.Scalar(), kv.second, shown, kv.first.Mark(), study.varied);
  if (const auto derived = root["derived"]; derived && derived.IsMap()) {
    study.derived.clear();
    for (const auto& kv : derived)
      study.derived.push_back({kv.first.Scalar(), kv.second, at(shown, kv.first.Mark()), at(shown, kv.first.Mark())});
  }
}

bool is_study(const YAML::Node& root) { return root.IsMap() && (root["study"] || root["vary"]); }

// Keys without a dot are the study's own variables (beta_factor), not scene keys.
bool scene_key(const std::string& key) { return key.find('.') != std::string::npos; }

int check_study(const std::string& file, const std::vector<std::string>& cli_overrides) {
  Study study;
  study.file = file;
  read_study(file, file, study, 0);
  if (study.scene.empty()) throw ConfigError(file + ": a study needs 'scene' (the scene file it varies)");
  std::vector<std::string> overrides;
  schema::CheckOptions options;
  for (const auto& f : study.fixed) {
    if (!scene_key(f.key)) continue;
    overrides.push_back(f.key + "=" + emit(f.value));
    options.override_origins.push_back({overrides.back(), f.where});
  }
  overrides.insert(overrides.end(), cli_overrides.begin(), cli_overrides.end());
  const Scene scene = Scene::load(study.scene, overrides);
  const auto base = schema::check_scene(scene, options);
  std::vector<schema::Problem> problems = base.problems;
  std::set<std::string> seen;
  for (const auto& p : problems) seen.insert(p.text());
  // Every value a varied key takes (alone, on top of the fixed keys), and the names of the
  // derived keys: problems at the study's line of that key or value.
  std::vector<StudyKey> keys = study.varied;
  for (const auto& d : study.derived) keys.push_back({d.key, YAML::Node("1"), d.where, d.where});
  for (const auto& k : keys) {
    if (!scene_key(k.key)) continue;
    const bool derived =
        std::any_of(study.derived.begin(), study.derived.end(), [&](const StudyKey& d) { return d.where == k.where; });
    auto with = overrides;
    with.push_back(k.key + "=" + emit(k.value));
    auto opts = options;
    opts.override_origins.push_back({with.back(), k.where});
    for (auto p : schema::check_scene(Scene::load(study.scene, with), opts).problems) {
      if (p.where != k.where) continue;
      const bool name = p.message.rfind("unknown", 0) == 0 || p.message.find("is only used") != std::string::npos;
      if (derived && !name) continue;   // a derived value is an expression: only its name is checked here
      if (name) p.where = k.key_where;  // a problem of the key, not of one of its values
      if (seen.insert(p.text()).second) problems.push_back(p);
    }
  }
  if (!problems.empty()) {
    print(problems);
    return 1;
  }
  std::cout << fmt::format("OK: {} (scene {}, {} keys checked)\n", file, study.scene.string(), base.keys_checked);
  return 0;
}

}  // namespace

int check_file(const std::string& file, const std::vector<std::string>& overrides) {
  try {
    YAML::Node root;
    try {
      root = YAML::LoadFile(file);
    } catch (const YAML::BadFile&) {
      throw ConfigError("cannot open '" + file + "'");
    } catch (const YAML::Exception&) {
      // Scene::load says where the YAML is broken.
    }
    if (is_study(root)) return check_study(file, overrides);
    const Scene scene = Scene::load(file, overrides);
    const auto result = schema::check_scene(scene);
    if (!result.ok()) {
      print(result.problems);
      return 1;
    }
    std::cout << fmt::format("OK: {} ({} keys checked)\n", file, result.keys_checked);
    return 0;
  } catch (const ConfigError& e) {
    std::cerr << e.what() << "\n";
    return 1;
  }
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
