#include "fsi/common/config.hpp"

#include <fmt/format.h>

#include <cmath>
#include <fstream>
#include <map>
#include <sstream>

#include "fsi/common/scene_schema.hpp"
#include "fsi/common/utf8.hpp"

namespace fsi {

namespace detail {
std::vector<std::string> split_dotted(const std::string& key) {
  std::vector<std::string> parts;
  std::stringstream ss(key);
  std::string part;
  while (std::getline(ss, part, '.')) parts.push_back(part);
  return parts;
}

}  // namespace detail

using detail::split_dotted;

namespace {

std::string mark_string(const std::string& origin, const YAML::Mark& mark) {
  if (mark.is_null()) return origin + " (--set)";
  return origin + ":" + std::to_string(mark.line + 1) + ":" + std::to_string(mark.column + 1);
}

void apply_override(YAML::Node root, const std::string& assignment, const std::string& origin) {
  const auto eq = assignment.find('=');
  if (eq == std::string::npos || eq == 0) throw ConfigError("--set '" + assignment + "': expected dotted.key=value");
  const auto parts = split_dotted(assignment.substr(0, eq));
  YAML::Node value;
  try {
    value = YAML::Load(assignment.substr(eq + 1));
  } catch (const YAML::Exception& e) {
    throw ConfigError("--set '" + assignment + "': value is not valid YAML: " + e.msg);
  }
  // Walk with explicit node copies: yaml-cpp's operator[] on a reference re-binds.
  std::vector<YAML::Node> chain{root};
  for (std::size_t i = 0; i + 1 < parts.size(); ++i) {
    YAML::Node next = chain.back()[parts[i]];
    if (next && !next.IsMap())
      throw ConfigError("--set '" + assignment + "': '" + parts[i] + "' in " + origin + " is not a section");
    chain.push_back(next);
  }
  chain.back()[parts.back()] = value;
}

// A scene is a few hundred nodes; aliases (*a) of nested anchors (&a) let a few lines name
// 2^40 of them, and a walk over the tree visits every one (fuzz/corpus/fuzz_scene/regress_alias_bomb).
constexpr std::size_t kMaxSceneNodes = 100000;
// An alias inside its own anchor (`a: &a [*a]`) makes the tree a cycle: a walk would recurse
// until the stack overflows (fuzz/corpus/fuzz_scene/regress_alias_cycle). Scenes nest 4 deep.
constexpr int kMaxSceneDepth = 64;

// yaml-cpp keeps the last of two equal keys silently: refuse them, naming both lines.
void check_duplicates(const YAML::Node& node, const std::string& path, const std::string& origin, std::size_t& visited,
                      int depth = 0) {
  if (depth > kMaxSceneDepth)
    throw ConfigError(origin + ": '" + path + "' is nested more than " + std::to_string(kMaxSceneDepth) +
                      " levels deep; is an anchor (&) used inside itself?");
  if (++visited > kMaxSceneNodes)
    throw ConfigError(origin + ": the scene has more than " + std::to_string(kMaxSceneNodes) +
                      " values (counting every use of an alias); is an anchor (&) used recursively?");
  if (node.IsMap()) {
    std::map<std::string, YAML::Mark> seen;
    for (const auto& kv : node) {
      const std::string key = kv.first.Scalar();
      const std::string full = path.empty() ? key : path + "." + key;
      const auto [it, fresh] = seen.emplace(key, kv.first.Mark());
      if (!fresh)
        throw ConfigError(mark_string(origin, kv.first.Mark()) + ": duplicate key '" + full + "' (first at " +
                          mark_string(origin, it->second) + ")");
      check_duplicates(kv.second, full, origin, visited, depth + 1);
    }
  } else if (node.IsSequence()) {
    for (std::size_t i = 0; i < node.size(); ++i)
      check_duplicates(node[i], path + "[" + std::to_string(i) + "]", origin, visited, depth + 1);
  }
}

void collect_unused(const YAML::Node& node, const std::string& path, const std::set<std::string>& used,
                    const std::string& origin, std::vector<std::string>& unknown) {
  if (!node.IsMap()) return;
  for (const auto& kv : node) {
    const std::string key = kv.first.Scalar();
    const std::string full = path.empty() ? key : path + "." + key;
    if (!used.count(full)) {
      // The closest key read next to it, if it is a likely typo of one.
      std::vector<std::string> siblings;
      const std::string prefix = path.empty() ? "" : path + ".";
      for (const auto& u : used)
        if (u.rfind(prefix, 0) == 0 && u.find_first_of(".[", prefix.size()) == std::string::npos)
          siblings.push_back(u.substr(prefix.size()));
      const std::string suggestion = schema::closest(key, siblings);
      unknown.push_back("'" + full + "' at " + mark_string(origin, kv.first.Mark()) +
                        (suggestion.empty() ? "" : " (did you mean '" + suggestion + "'?)"));
    } else if (kv.second.IsMap()) {
      collect_unused(kv.second, full, used, origin, unknown);
    } else if (kv.second.IsSequence()) {
      for (std::size_t i = 0; i < kv.second.size(); ++i)
        collect_unused(kv.second[i], full + "[" + std::to_string(i) + "]", used, origin, unknown);
    }
  }
}

}  // namespace

namespace {

// "file:line:col" of byte `offset` of `text`.
std::string place_of(const std::string& text, const std::string& origin, std::size_t offset) {
  std::size_t line = 1, column = 1;
  for (std::size_t i = 0; i < offset && i < text.size(); ++i) {
    if (text[i] == '\n')
      ++line, column = 1;
    else if ((static_cast<unsigned char>(text[i]) & 0xC0) != 0x80)
      ++column;  // count characters
  }
  return fmt::format("{}:{}:{}", origin, line, column);
}

// A scene is UTF-8 text without NUL bytes: refused otherwise, naming the place (the YAML reader
// would take a NUL for the end of a value, and a server could not send the text on).
void refuse_unreadable_bytes(const std::string& text, const std::string& origin, const std::string& override_text) {
  const std::string where_prefix = override_text.empty() ? "" : " (--set " + valid_utf8(override_text) + ")";
  if (text.size() >= 2 && ((text[0] == '\xFF' && text[1] == '\xFE') || (text[0] == '\xFE' && text[1] == '\xFF')))
    throw ConfigError(origin + where_prefix + ": the file is UTF-16 text; save the scene as UTF-8");
  if (const auto nul = text.find('\0'); nul != std::string::npos)
    throw ConfigError((override_text.empty() ? place_of(text, origin, nul) : origin + where_prefix) +
                      ": a NUL byte (0x00) in the scene; a scene is UTF-8 text");
  if (const auto bad = first_invalid_utf8(text); bad != std::string::npos)
    throw ConfigError(
        fmt::format("{}: byte 0x{:02X} is not UTF-8 (a Latin-1 or other 8-bit character?); save the "
                    "scene as UTF-8",
                    override_text.empty() ? place_of(text, origin, bad) : origin + where_prefix,
                    static_cast<unsigned char>(text[bad])));
}

}  // namespace

Scene Scene::parse(const std::string& text, const std::string& origin, const std::vector<std::string>& overrides) {
  Scene scene;
  scene.state_ = std::make_shared<State>();
  scene.state_->origin = origin;
  scene.state_->text = text;
  scene.state_->overrides = overrides;
  refuse_unreadable_bytes(text, origin, "");
  for (const auto& o : overrides) refuse_unreadable_bytes(o, origin, o);
  try {
    scene.state_->root = YAML::Load(text);
  } catch (const YAML::ParserException& e) {
    // YAML forbids tabs in indentation; yaml-cpp then reports the structure it lost ("end of
    // map not found"), not the tab: name the first line indented with one.
    std::string hint;
    std::istringstream lines(text);
    int number = 0;
    for (std::string line; std::getline(lines, line);) {
      ++number;
      const auto content = line.find_first_not_of(" \t");
      if (content != std::string::npos && line.find('\t') < content) {
        hint = fmt::format(" (line {} is indented with a tab: YAML takes spaces only)", number);
        break;
      }
    }
    throw ConfigError(mark_string(origin, e.mark) + ": not valid YAML: " + e.msg + hint);
  }
  if (!scene.state_->root || scene.state_->root.IsNull()) scene.state_->root = YAML::Node(YAML::NodeType::Map);
  if (!scene.state_->root.IsMap()) throw ConfigError(origin + ": a scene must be a YAML map of sections");
  std::size_t visited = 0;
  check_duplicates(scene.state_->root, "", origin, visited);
  for (const auto& o : overrides) apply_override(scene.state_->root, o, origin);
  return scene;
}

Scene Scene::load(const std::filesystem::path& path, const std::vector<std::string>& overrides) {
  std::ifstream in(path);
  if (!in) throw ConfigError("cannot open scene file '" + path.string() + "'");
  std::stringstream buffer;
  buffer << in.rdbuf();
  return parse(buffer.str(), path.string(), overrides);
}

bool Scene::has(const std::string& dotted_key) const {
  YAML::Node node = state_->root;
  for (const auto& part : split_dotted(dotted_key)) {
    if (!node.IsMap()) return false;
    const YAML::Node next = node[part];  // note: Node::operator= would assign, not rebind
    if (!next) return false;
    node.reset(next);
  }
  return true;
}

ConfigSection Scene::root() const { return ConfigSection(state_, state_->root, ""); }

std::string Scene::name() const {
  const auto r = root();
  r.get<std::string>("description", "");  // documentation only
  return r.get<std::string>("scene", "");
}

ConfigSection Scene::section(const std::string& name) const { return root().child(name); }

void Scene::check_all_used(const std::string& prefix) const {
  std::vector<std::string> unknown;
  YAML::Node node = state_->root;
  if (!prefix.empty()) {
    for (const auto& part : split_dotted(prefix)) {
      if (!node.IsMap()) return;
      const YAML::Node next = node[part];
      if (!next) return;
      node.reset(next);
    }
    if (!state_->used.count(prefix)) {
      throw ConfigError("section '" + prefix + "' in " + state_->origin + " was not read");
    }
  }
  collect_unused(node, prefix, state_->used, state_->origin, unknown);
  if (unknown.empty()) return;
  std::string msg = "unknown key" + std::string(unknown.size() > 1 ? "s" : "") + " in scene: ";
  for (std::size_t i = 0; i < unknown.size(); ++i) msg += (i ? ", " : "") + unknown[i];
  throw ConfigError(msg);
}

ConfigSection::ConfigSection(std::shared_ptr<Scene::State> state, YAML::Node node, std::string path)
    : state_(std::move(state)), node_(node), path_(std::move(path)) {}

std::string ConfigSection::full_key(const std::string& key) const { return path_.empty() ? key : path_ + "." + key; }

YAML::Node ConfigSection::lookup(const std::string& key) const {
  state_->used.insert(full_key(key));
  if (node_.IsMap())
    for (const auto& kv : node_)
      if (kv.first.Scalar() == key) return kv.second;
  return YAML::Node(YAML::NodeType::Undefined);  // tests false with operator!
}

bool ConfigSection::node_is_scalar(const std::string& key) const {
  if (node_.IsMap())
    for (const auto& kv : node_)
      if (kv.first.Scalar() == key) return kv.second.IsScalar();
  return false;
}

bool ConfigSection::given(const std::string& key) const {
  const YAML::Node value = lookup(key);
  return value && !value.IsNull();
}

ConfigSection ConfigSection::child_or_empty(const std::string& key) const {
  if (given(key)) return child(key);
  return ConfigSection(state_, YAML::Node(YAML::NodeType::Map), full_key(key));
}

bool ConfigSection::has(const std::string& key) const {
  if (!node_.IsMap()) return false;
  for (const auto& kv : node_)
    if (kv.first.Scalar() == key) return true;
  return false;
}

std::string ConfigSection::where(const std::string& key) const {
  if (node_.IsMap())
    for (const auto& kv : node_)
      if (kv.first.Scalar() == key) return mark_string(state_->origin, kv.first.Mark());
  return mark_string(state_->origin, node_.Mark());
}

void ConfigSection::fail(const std::string& key, const std::string& message) const {
  throw ConfigError(where(key) + ": '" + full_key(key) + "' " + message);
}

ConfigSection ConfigSection::child(const std::string& key) const {
  YAML::Node value = lookup(key);
  if (!value) fail(key, "is required but missing (a section)");
  if (!value.IsMap()) fail(key, "must be a section (a map of keys)");
  return ConfigSection(state_, value, full_key(key));
}

std::optional<ConfigSection> ConfigSection::optional_child(const std::string& key) const {
  if (!has(key)) return std::nullopt;
  return child(key);
}

std::vector<ConfigSection> ConfigSection::list(const std::string& key) const {
  YAML::Node value = lookup(key);
  std::vector<ConfigSection> items;
  if (!value || value.IsNull()) return items;
  if (!value.IsSequence()) fail(key, "must be a list");
  for (std::size_t i = 0; i < value.size(); ++i) {
    const std::string item_path = full_key(key) + "[" + std::to_string(i) + "]";
    state_->used.insert(item_path);
    items.emplace_back(state_, value[i], item_path);
  }
  return items;
}

std::filesystem::path ConfigSection::scene_dir() const {
  std::filesystem::path origin(state_->origin);
  return origin.has_parent_path() ? origin.parent_path() : std::filesystem::path(".");
}

std::filesystem::path ConfigSection::get_path(const std::string& key) const {
  namespace fs = std::filesystem;
  const fs::path given(get<std::string>(key));
  if (given.is_absolute()) {
    if (!fs::exists(given)) fail(key, "file '" + given.string() + "' does not exist");
    return given;
  }
  const std::vector<fs::path> candidates = {scene_dir() / given, given, fs::path("configs") / given};
  for (const auto& c : candidates)
    if (fs::exists(c)) return fs::absolute(c);
  std::string tried;
  for (const auto& c : candidates) tried += (tried.empty() ? "" : ", ") + c.string();
  fail(key, "file '" + given.string() + "' not found (tried " + tried + ")");
}

std::vector<std::string> ConfigSection::keys() const {
  std::vector<std::string> out;
  if (node_.IsMap())
    for (const auto& kv : node_) out.push_back(kv.first.Scalar());
  return out;
}

std::array<double, 2> read_vector2(const ConfigSection& section, const std::string& key) {
  if (!section.has(key)) {
    section.get<double>(key, 0.0);  // marks the key as read
    return {0.0, 0.0};
  }
  if (section.node_is_scalar(key)) return {section.get<double>(key), 0.0};
  {
    const auto v = section.get<std::vector<double>>(key);
    if (v.size() != 2) section.fail(key, "must be a number or a list [x, y]");
    for (double x : v)
      if (!std::isfinite(x)) section.fail(key, "must be finite");
    return {v[0], v[1]};
  }
}

}  // namespace fsi
