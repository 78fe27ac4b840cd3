#pragma once
// Scene files (YAML) with strict checking: every key a component reads is recorded, and
// `check_all_used()` turns any key nobody read into an error naming the key and the line.
// A wrong type is an error naming the key, the expected type and the line.
//
// Usage:
//   auto scene = fsi::Scene::load("configs/sdof_model.yaml", {"solid.mass=2"});
//   auto solid = scene.section("solid");
//   double m = solid.get<double>("mass");            // required
//   double c = solid.get<double>("damping", 0.0);    // optional with default
//   scene.check_all_used("solid");                   // throws fsi::ConfigError on typos
#include <yaml-cpp/yaml.h>

#include <array>
#include <filesystem>
#include <memory>
#include <optional>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

namespace fsi {

class ConfigError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class ConfigSection;

class Scene {
 public:
  // Parses `text` (the file's content); `origin` names it in error messages.
  static Scene parse(const std::string& text, const std::string& origin,
                     const std::vector<std::string>& overrides = {});
  static Scene load(const std::filesystem::path& path, const std::vector<std::string>& overrides = {});

  const std::string& origin() const { return state_->origin; }
  const std::string& text() const { return state_->text; }
  const std::vector<std::string>& overrides() const { return state_->overrides; }
  bool has(const std::string& dotted_key) const;
  // The scene's `scene` name (also marks `scene` and `description` as read).
  std::string name() const;
  ConfigSection root() const;
  const YAML::Node& root_node() const { return state_->root; }
  ConfigSection section(const std::string& name) const;  // required map
  // Throws ConfigError listing every key under `prefix` ("" = whole file) never read.
  void check_all_used(const std::string& prefix = "") const;

 private:
  friend class ConfigSection;
  struct State {
    std::string origin;
    std::string text;
    std::vector<std::string> overrides;
    YAML::Node root;
    std::set<std::string> used;  // dotted keys that were read
  };
  std::shared_ptr<State> state_;
};

class ConfigSection {
 public:
  ConfigSection(std::shared_ptr<Scene::State> state, YAML::Node node, std::string path);

  // The key is present and holds a scalar (not a list or a section).
  bool node_is_scalar(const std::string& key) const;
  bool has(const std::string& key) const;
  // The key is present with a value (not empty, `key:`); marks it as read.
  bool given(const std::string& key) const;
  template <class T>
  T get(const std::string& key) const;  // required
  template <class T>
  T get(const std::string& key, const T& fallback) const;
  ConfigSection child(const std::string& key) const;  // required map
  std::optional<ConfigSection> optional_child(const std::string& key) const;
  // The child map if given, otherwise an empty section at its path (its keys take defaults).
  ConfigSection child_or_empty(const std::string& key) const;
  std::vector<ConfigSection> list(const std::string& key) const;  // sequence of maps
  std::vector<std::string> keys() const;
  const std::string& path() const { return path_; }
  // The scene this section belongs to (a remote solver is sent the whole text).
  const std::string& scene_text() const { return state_->text; }
  const std::string& scene_origin() const { return state_->origin; }
  const std::vector<std::string>& scene_overrides() const { return state_->overrides; }
  // Directory of the scene file, for resolving relative paths (mesh files).
  std::filesystem::path scene_dir() const;
  // Resolves a path key (the one resolver of scene paths): absolute; else relative to the
  // scene file's folder, the working folder, or configs/ under it, the first that exists; a
  // ConfigError naming the places tried when none does.
  std::filesystem::path get_path(const std::string& key) const;
  std::string where(const std::string& key) const;  // "file:line:col" of a key
  std::string full_key(const std::string& key) const;
  // An error that names the key and its place, e.g. for a value out of range.
  [[noreturn]] void fail(const std::string& key, const std::string& message) const;

 private:
  YAML::Node lookup(const std::string& key) const;
  template <class T>
  T convert(const std::string& key, const YAML::Node& value) const;
  std::shared_ptr<Scene::State> state_;
  YAML::Node node_;
  std::string path_;
};

// Reads a 2-vector given as a number (the x component, y = 0) or a list [x, y]; absent = 0.
std::array<double, 2> read_vector2(const ConfigSection& section, const std::string& key);

}  // namespace fsi

#include "fsi/common/config_impl.hpp"
