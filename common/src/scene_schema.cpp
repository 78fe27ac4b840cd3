// Checks a scene against the declared scene keys (scene_declare.cpp) and writes the reference.
#include "fsi/common/scene_schema.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <sstream>

#include "fsi/common/standalone.hpp"

namespace fsi::schema {

std::size_t edit_distance(const std::string& a, const std::string& b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diagonal = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t up = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diagonal = up;
    }
  }
  return row[b.size()];
}

std::string closest(const std::string& word, const std::vector<std::string>& candidates) {
  std::string best;
  std::size_t best_distance = 0;
  for (const auto& c : candidates) {
    const std::size_t d = edit_distance(word, c);
    if (best.empty() || d < best_distance) best = c, best_distance = d;
  }
  // Close enough: a typo or two, or a third of the word.
  if (best.empty() || best_distance == 0 || best_distance > std::max<std::size_t>(2, word.size() / 3)) return "";
  return best;
}

namespace {

std::string join(const std::vector<std::string>& items, const std::string& sep = ", ") {
  std::string out;
  for (const auto& s : items) out += (out.empty() ? "" : sep) + s;
  return out;
}

std::string number_text(double v) { return fmt::format("{:g}", v); }

std::string range_text(const Key& k) {
  if (k.lo && k.hi)
    return fmt::format("in {}{}, {}{}", k.lo_open ? "(" : "[", number_text(*k.lo), number_text(*k.hi),
                       k.hi_open ? ")" : "]");
  if (k.lo) {
    if (*k.lo == 0 && k.lo_open) return "positive";
    return fmt::format("{} {}", k.lo_open ? ">" : ">=", number_text(*k.lo));
  }
  if (k.hi) return fmt::format("{} {}", k.hi_open ? "<" : "<=", number_text(*k.hi));
  return "";
}

}  // namespace

std::string range_problem(const Key& k, double value) {
  if (!k.allowed.empty()) {
    for (const auto& a : k.allowed)
      if (std::stod(a) == value) return "";
    return "must be " + join(k.allowed, " or ");
  }
  const bool low = k.lo && (k.lo_open ? !(value > *k.lo) : !(value >= *k.lo));
  const bool high = k.hi && (k.hi_open ? !(value < *k.hi) : !(value <= *k.hi));
  if (!low && !high) return "";
  return k.range_message.empty() ? "must be " + range_text(k) : k.range_message;
}

namespace {

const char* type_text(Type t) {
  switch (t) {
    case Type::Number:
      return "a number";
    case Type::Integer:
      return "an integer";
    case Type::Bool:
      return "a boolean (true/false)";
    case Type::String:
      return "a string";
    case Type::Enum:
      return "one of";
    case Type::Vector2:
      return "a list of 2 numbers [x, y]";
    case Type::NumberOrVector2:
      return "a number or a list [x, y]";
    case Type::Vector:
      return "a list [x, y] or [x, y, z]";
    case Type::NumberOrVector:
      return "a number or a list [x, y] or [x, y, z]";
    case Type::Names:
      return "a name or a list of names";
    case Type::StringList:
      return "a list of names";
    case Type::IntList:
      return "a list of integers";
    case Type::PointPair:
      return "[[x0, y0], [x1, y1]]";
    case Type::Section:
      return "a section (a map of keys)";
    case Type::SectionList:
      return "a list of sections";
    case Type::NamedMap:
      return "a map of names";
  }
  return "";
}

const char* short_type(Type t) {
  switch (t) {
    case Type::Number:
      return "number";
    case Type::Integer:
      return "integer";
    case Type::Bool:
      return "bool";
    case Type::String:
      return "string";
    case Type::Enum:
      return "enum";
    case Type::Vector2:
      return "[x, y]";
    case Type::NumberOrVector2:
      return "number or [x, y]";
    case Type::Vector:
      return "[x, y] or [x, y, z]";
    case Type::NumberOrVector:
      return "number, [x, y] or [x, y, z]";
    case Type::Names:
      return "name or list of names";
    case Type::StringList:
      return "list of names";
    case Type::IntList:
      return "list of integers";
    case Type::PointPair:
      return "[[x0, y0], [x1, y1]]";
    case Type::Section:
      return "section";
    case Type::SectionList:
      return "list of sections";
    case Type::NamedMap:
      return "map";
  }
  return "";
}

std::string scalar_text(const YAML::Node& v) {
  if (v.IsScalar()) return "'" + v.Scalar() + "'";
  if (v.IsSequence()) return "a list";
  if (v.IsMap()) return "a section";
  return "nothing";
}

bool is_number(const YAML::Node& v, double* out = nullptr) {
  if (!v.IsScalar()) return false;
  try {
    const double d = v.as<double>();
    if (!std::isfinite(d)) return false;
    if (out) *out = d;
    return true;
  } catch (const YAML::Exception&) {
    return false;
  }
}

bool is_integer(const YAML::Node& v, double* out = nullptr) {
  if (!v.IsScalar()) return false;
  try {
    const long long i = v.as<long long>();
    if (out) *out = static_cast<double>(i);
    return true;
  } catch (const YAML::Exception&) {
    return false;
  }
}

bool is_bool(const YAML::Node& v) {
  if (!v.IsScalar()) return false;
  try {
    (void)v.as<bool>();
    return true;
  } catch (const YAML::Exception&) {
    return false;
  }
}

bool numbers(const YAML::Node& v, std::size_t n) {
  if (!v.IsSequence() || v.size() != n) return false;
  for (std::size_t i = 0; i < n; ++i)
    if (!is_number(v[i])) return false;
  return true;
}

bool strings(const YAML::Node& v) {
  if (!v.IsSequence()) return false;
  for (std::size_t i = 0; i < v.size(); ++i)
    if (!v[i].IsScalar()) return false;
  return true;
}

YAML::Node find_key(const YAML::Node& map, const std::string& name) {
  if (map.IsMap())
    for (const auto& kv : map)
      if (kv.first.Scalar() == name) return kv.second;
  return YAML::Node(YAML::NodeType::Undefined);
}

class Checker {
 public:
  Checker(const Scene& scene, const CheckOptions& options) : scene_(scene), options_(options) {
    for (const auto& o : scene.overrides()) {
      const auto eq = o.find('=');
      overrides_.push_back({eq == std::string::npos ? o : o.substr(0, eq), o});
    }
  }

  CheckResult run() {
    const YAML::Node root = scene_.root_node();
    check_map(root, scene_keys(), "", YAML::Mark::null_mark(), true);
    if (!options_.only_sections.empty()) return std::move(result_);
    // Which processes the scene starts.
    const auto has = [&](const char* key) { return static_cast<bool>(find_key(root, key)); };
    const bool coupled = has("coupling"), solid = has("solid"), fluid = has("fluid");
    if (coupled && (!solid || !fluid))
      add("", "", fmt::format("{}: a coupled scene (with 'coupling') needs 'solid' and 'fluid'", scene_.origin()));
    if (!coupled && solid == fluid)
      add("", "",
          fmt::format("{}: a scene without 'coupling' must have exactly one of 'solid' or 'fluid'", scene_.origin()));
    return std::move(result_);
  }

 private:
  bool wanted(const std::string& section) const {
    if (std::find(options_.skip_sections.begin(), options_.skip_sections.end(), section) !=
        options_.skip_sections.end())
      return false;
    return options_.only_sections.empty() || std::find(options_.only_sections.begin(), options_.only_sections.end(),
                                                       section) != options_.only_sections.end();
  }

  // The override (its text) that set `path`, or "".
  std::string override_of(const std::string& path) const {
    std::string found;
    for (const auto& [key, text] : overrides_)
      if (path == key || path.rfind(key + ".", 0) == 0) found = text;
    return found;
  }
  std::string override_under(const std::string& path) const {
    std::string found;
    for (const auto& [key, text] : overrides_)
      if (key.rfind(path + ".", 0) == 0) found = text;
    return found;
  }
  std::string override_where(const std::string& text) const {
    for (const auto& [assignment, where] : options_.override_origins)
      if (assignment == text) return where;
    return scene_.origin() + " (--set " + text + ")";
  }

  // Where the key `path` (its key node's mark) is: in the file, or the override that set it.
  std::string where(const std::string& path, const YAML::Mark& mark) const {
    if (const auto o = override_of(path); !o.empty()) return override_where(o);
    if (mark.is_null()) {
      if (const auto o = override_under(path); !o.empty()) return override_where(o);
      return scene_.origin();
    }
    return fmt::format("{}:{}:{}", scene_.origin(), mark.line + 1, mark.column + 1);
  }

  void add(const std::string& where, const std::string& key, const std::string& message) {
    result_.problems.push_back({where, message, key});
  }

  static std::string full(const std::string& path, const std::string& name) {
    return path.empty() ? name : path + "." + name;
  }

  bool holds(const Condition& c, const YAML::Node& map) const {
    YAML::Node value;
    if (c.key.find('.') == std::string::npos) {
      value = find_key(map, c.key);
    } else {
      value.reset(scene_.root_node());
      for (const auto& part : fsi::detail::split_dotted(c.key)) {
        const YAML::Node next = find_key(value, part);
        value.reset(next);
        if (!value) break;
      }
    }
    if (c.values.empty()) return value && !value.IsNull();
    const std::string v = value && value.IsScalar() ? value.Scalar() : c.fallback;
    return std::find(c.values.begin(), c.values.end(), v) != c.values.end();
  }
  bool applies(const Key& k, const YAML::Node& map) const {
    for (const auto& c : k.when)
      if (!holds(c, map)) return false;
    return true;
  }
  static std::string condition_text(const Condition& c, const std::string& path) {
    const std::string key = c.key.find('.') == std::string::npos ? full(path, c.key) : c.key;
    if (c.values.empty()) return "when '" + key + "' is given";
    return "when '" + key + "' is " + join(c.values, " or ");
  }

  // Checks the keys of `map` against `keys`; `path` is the map's dotted key, `mark` its key's place.
  void check_map(const YAML::Node& map, const std::vector<Key>& keys, const std::string& path, const YAML::Mark& mark,
                 bool top = false) {
    std::vector<std::string> valid;  // names usable here
    for (const auto& k : keys)
      if (applies(k, map)) valid.push_back(k.name);
    std::set<std::string> explained;  // required keys a misspelt key already names
    std::map<std::string, std::vector<std::string>> groups_given;
    for (const auto& kv : map) {
      const std::string name = kv.first.Scalar();
      const std::string key = full(path, name);
      if (top && !wanted(name)) continue;
      ++result_.keys_checked;
      const std::string at = where(key, kv.first.Mark());
      const auto spec = std::find_if(keys.begin(), keys.end(), [&](const Key& k) { return k.name == name; });
      if (spec == keys.end()) {
        std::string message = top ? fmt::format("unknown section '{}'", key) : fmt::format("unknown key '{}'", key);
        const std::string suggestion = closest(name, valid);
        if (!suggestion.empty()) {
          message += fmt::format(" (did you mean '{}'?)", suggestion);
          const auto s = std::find_if(keys.begin(), keys.end(), [&](const Key& k) { return k.name == suggestion; });
          if (s->required && !find_key(map, suggestion) && !explained.count(suggestion)) {
            message += fmt::format("; the required key '{}' is missing", full(path, suggestion));
            explained.insert(suggestion);
          }
        } else {
          message += top ? "; known sections: " + join(valid) : "; known keys here: " + join(valid);
        }
        add(at, key, message);
        continue;
      }
      if (!applies(*spec, map)) {
        for (const auto& c : spec->when)
          if (!holds(c, map)) {
            add(at, key, fmt::format("'{}' is only used {}", key, condition_text(c, path)));
            break;
          }
        continue;
      }
      if (!spec->one_of.empty()) groups_given[spec->one_of].push_back(name);
      check_value(*spec, kv.second, key, at, kv.first.Mark());
    }
    // Missing required keys and one-of groups.
    const std::string section_at = path.empty() ? scene_.origin() : where(path, mark);
    std::set<std::string> groups_seen;
    for (const auto& k : keys) {
      if (!applies(k, map)) continue;
      if (top && !wanted(k.name)) continue;
      if (k.required && !find_key(map, k.name) && !explained.count(k.name))
        add(section_at, full(path, k.name),
            fmt::format("'{}' is required but missing{}", full(path, k.name),
                        k.type == Type::Section ? " (a section)" : ""));
      if (!k.one_of.empty() && groups_seen.insert(k.one_of).second) {
        std::vector<std::string> members;
        for (const auto& m : keys)
          if (m.one_of == k.one_of && applies(m, map)) members.push_back(m.name);
        const auto& given = groups_given[k.one_of];
        if (given.size() != 1) {
          const std::string which = join(members, " or ");
          if (given.empty())
            add(section_at, path, fmt::format("'{}' needs one of {}", path, which));
          else
            add(where(full(path, given[1]), mark_of(map, given[1])), full(path, given[1]),
                fmt::format("give exactly one of {} in '{}' (both '{}' and '{}' are given)", which, path, given[0],
                            given[1]));
        }
      }
    }
  }

  static YAML::Mark mark_of(const YAML::Node& map, const std::string& name) {
    for (const auto& kv : map)
      if (kv.first.Scalar() == name) return kv.first.Mark();
    return YAML::Mark::null_mark();
  }

  void type_error(const Key& k, const YAML::Node& v, const std::string& key, const std::string& at) {
    std::string expected = type_text(k.type);
    if (k.type == Type::Enum) expected += " " + join(k.allowed);
    if (k.type == Type::IntList && k.size) expected = fmt::format("a list of {} integers", k.size);
    if (k.type == Type::StringList && k.size) expected = fmt::format("a list of {} names", k.size);
    add(at, key,
        fmt::format("'{}' must be {}, got {}", key, expected, v.IsScalar() ? "'" + v.Scalar() + "'" : scalar_text(v)));
  }

  void check_range(const Key& k, double value, const YAML::Node& v, const std::string& key, const std::string& at) {
    if (const auto problem = range_problem(k, value); !problem.empty())
      add(at, key, fmt::format("'{}' {}, got '{}'", key, problem, v.Scalar()));
  }

  void check_value(const Key& k, const YAML::Node& v, const std::string& key, const std::string& at,
                   const YAML::Mark& mark) {
    const bool container = k.type == Type::Section || k.type == Type::NamedMap;
    if (v.IsNull() && !container) {
      if (k.required) type_error(k, v, key, at);
      return;  // an empty optional value takes the default
    }
    double d = 0;
    switch (k.type) {
      case Type::Number:
        if (!is_number(v, &d)) return type_error(k, v, key, at);
        return check_range(k, d, v, key, at);
      case Type::Integer:
        if (!is_integer(v, &d)) return type_error(k, v, key, at);
        return check_range(k, d, v, key, at);
      case Type::Bool:
        if (!is_bool(v)) return type_error(k, v, key, at);
        return;
      case Type::String:
        if (!v.IsScalar()) return type_error(k, v, key, at);
        return;
      case Type::Enum: {
        if (!v.IsScalar()) return type_error(k, v, key, at);
        if (std::find(k.allowed.begin(), k.allowed.end(), v.Scalar()) != k.allowed.end()) return;
        std::string message = fmt::format("'{}' must be one of {}, got '{}'", key, join(k.allowed), v.Scalar());
        if (const auto s = closest(v.Scalar(), k.allowed); !s.empty())
          message += fmt::format(" (did you mean '{}'?)", s);
        return add(at, key, message);
      }
      case Type::Vector2:
        if (!numbers(v, 2) && !(k.size == 3 && numbers(v, 3)))
          return type_error(k, v, key, at);  // count(3): [x, y] or [x, y, z]
        return;
      case Type::NumberOrVector2:
        if (!is_number(v) && !numbers(v, 2)) return type_error(k, v, key, at);
        return;
      case Type::Vector:
        if (!numbers(v, 2) && !numbers(v, 3)) return type_error(k, v, key, at);
        return;
      case Type::NumberOrVector:
        if (!is_number(v) && !numbers(v, 2) && !numbers(v, 3)) return type_error(k, v, key, at);
        return;
      case Type::Names:
        if (!v.IsScalar() && !strings(v)) return type_error(k, v, key, at);
        return;
      case Type::StringList:
        if (!strings(v) || (k.size && v.size() != static_cast<std::size_t>(k.size))) return type_error(k, v, key, at);
        return;
      case Type::IntList: {
        if (!v.IsSequence() || (k.size && v.size() != static_cast<std::size_t>(k.size)))
          return type_error(k, v, key, at);
        for (std::size_t i = 0; i < v.size(); ++i) {
          if (!is_integer(v[i]))
            return add(at, key,
                       fmt::format("'{}' must be a list of integers: entry {} is {}", key, i + 1,
                                   v[i].IsScalar() ? "'" + v[i].Scalar() + "'" : scalar_text(v[i])));
          check_range(k, v[i].as<double>(), v[i], fmt::format("{}[{}]", key, i), at);  // the key's range, per entry
        }
        return;
      }
      case Type::PointPair:
        if (!v.IsSequence() || v.size() != 2 || !numbers(v[0], 2) || !numbers(v[1], 2))
          return type_error(k, v, key, at);
        return;
      case Type::Section:
        if (!v.IsMap()) return type_error(k, v, key, at);
        if (!k.selector.empty()) return check_variant(k, v, key, at, mark);
        return check_map(v, k.children, key, mark);
      case Type::SectionList:
        if (!v.IsSequence()) return type_error(k, v, key, at);
        for (std::size_t i = 0; i < v.size(); ++i) {
          const std::string item = fmt::format("{}[{}]", key, i);
          if (!v[i].IsMap()) {
            add(at, item, fmt::format("'{}' must be a section (a map of keys), got {}", item, scalar_text(v[i])));
            continue;
          }
          check_map(v[i], k.children, item, mark);
        }
        return;
      case Type::NamedMap:
        if (!v.IsMap()) return type_error(k, v, key, at);
        for (const auto& kv : v) {
          const std::string item = full(key, kv.first.Scalar());
          ++result_.keys_checked;
          check_value(k.children.front(), kv.second, item, where(item, kv.first.Mark()), kv.first.Mark());
        }
        return;
    }
  }

  // A section whose keys depend on its selector key (solid.model).
  void check_variant(const Key& k, const YAML::Node& v, const std::string& key, const std::string& at,
                     const YAML::Mark& mark) {
    std::vector<std::string> values;
    for (const auto& variant : k.variants) values.push_back(variant.value);
    const YAML::Node selector = find_key(v, k.selector);
    const std::string selector_key = full(key, k.selector);
    if (!selector) {
      // A misspelt selector ('modle') is the likelier cause: check_map says so.
      for (const auto& kv : v)
        if (closest(kv.first.Scalar(), {k.selector}) == k.selector) {
          add(where(full(key, kv.first.Scalar()), kv.first.Mark()), full(key, kv.first.Scalar()),
              fmt::format("unknown key '{}' (did you mean '{}'?); the required key '{}' is missing (one of {})",
                          full(key, kv.first.Scalar()), k.selector, selector_key, join(values)));
          return;
        }
      add(at, selector_key, fmt::format("'{}' is required but missing (one of {})", selector_key, join(values)));
      return;
    }
    const auto variant = std::find_if(k.variants.begin(), k.variants.end(), [&](const Key::Variant& x) {
      return selector.IsScalar() && x.value == selector.Scalar();
    });
    if (variant == k.variants.end()) {
      const std::string selector_at = where(selector_key, mark_of(v, k.selector));
      std::string message =
          fmt::format("'{}' must be one of {}, got {}", selector_key, join(values), scalar_text(selector));
      if (selector.IsScalar())
        if (const auto s = closest(selector.Scalar(), values); !s.empty())
          message += fmt::format(" (did you mean '{}'?)", s);
      add(selector_at, selector_key, message);
      return;
    }
    std::vector<Key> keys = variant->keys;
    Key model = Key{};
    model.name = k.selector;
    model.type = Type::Enum;
    model.allowed = values;
    model.required = true;
    keys.insert(keys.begin(), model);
    const std::size_t before = result_.problems.size();
    check_map(v, keys, key, mark);
    // A key of another model: say so instead of a far-fetched suggestion.
    for (std::size_t i = before; i < result_.problems.size(); ++i) {
      auto& p = result_.problems[i];
      if (p.message.rfind("unknown key '", 0) != 0 || p.key.find('.', key.size() + 1) != std::string::npos) continue;
      const auto name = p.key.substr(key.size() + 1);
      for (const auto& other : k.variants) {
        if (&other == &*variant) continue;
        if (std::any_of(other.keys.begin(), other.keys.end(), [&](const Key& x) { return x.name == name; })) {
          p.message = fmt::format("unknown key '{}' for {} '{}' (it is a key of {} '{}')", p.key, selector_key,
                                  selector.Scalar(), selector_key, other.value);
          break;
        }
      }
    }
  }

  const Scene& scene_;
  const CheckOptions& options_;
  std::vector<std::pair<std::string, std::string>> overrides_;  // key, "key=value"
  CheckResult result_;
};

// Rules between keys that the table cannot say; they run when the section itself is clean.
void cross_checks(const Scene& scene, const CheckOptions& options, CheckResult& result) {
  const auto clean = [&](const std::string& section) {
    if (!scene.has(section)) return false;
    for (const auto& s : options.skip_sections)
      if (s == section) return false;
    if (!options.only_sections.empty() &&
        std::find(options.only_sections.begin(), options.only_sections.end(), section) == options.only_sections.end())
      return false;
    for (const auto& p : result.problems)
      if (p.key == section || p.key.rfind(section + ".", 0) == 0 || p.key.empty()) return false;
    return true;
  };
  const auto as_problem = [&](const std::string& key, auto&& fn) {
    try {
      fn();
    } catch (const ConfigError& e) {
      result.problems.push_back({"", e.what(), key});
    }
  };
  // Each section's rules between keys are its own reader's (time: end a whole number of steps;
  // coupling: beta below 2 with Algorithm 1), run on the scene.
  for (const auto& k : scene_keys())
    if (k.check && clean(k.name)) as_problem(k.name, [&] { k.check(scene); });
}

}  // namespace

CheckResult check_scene(const Scene& scene, const CheckOptions& options) {
  // A copy: the cross checks read through ConfigSection, which records what it read.
  const Scene copy = Scene::parse(scene.text(), scene.origin(), scene.overrides());
  CheckResult result = Checker(copy, options).run();
  cross_checks(copy, options, result);
  return result;
}

void require_valid(const Scene& scene, const std::vector<std::string>& sections) {
  const std::vector<Key> declared = scene_keys();
  std::vector<std::string> known;
  for (const auto& s : sections)
    if (std::any_of(declared.begin(), declared.end(), [&](const Key& k) { return k.name == s; }) && scene.has(s))
      known.push_back(s);
  // A model the schema does not know (a test's, an external server's) is the factory's business.
  known.erase(std::remove_if(known.begin(), known.end(),
                             [&](const std::string& s) {
                               const auto k = std::find_if(declared.begin(), declared.end(),
                                                           [&](const Key& x) { return x.name == s; });
                               if (k->selector.empty()) return false;
                               const YAML::Node model = find_key(find_key(scene.root_node(), s), k->selector);
                               return model && model.IsScalar() &&
                                      std::none_of(k->variants.begin(), k->variants.end(),
                                                   [&](const Key::Variant& v) { return v.value == model.Scalar(); });
                             }),
              known.end());
  if (known.empty()) return;
  CheckOptions options;
  options.only_sections = known;
  const CheckResult result = check_scene(scene, options);
  if (result.ok()) return;
  std::string message;
  for (const auto& p : result.problems) message += (message.empty() ? "" : "\n") + p.text();
  throw ConfigError(message);
}

void require_valid(const ConfigSection& section) {
  if (section.path().find('.') != std::string::npos) return;
  require_valid(Scene::parse(section.scene_text(), section.scene_origin(), section.scene_overrides()),
                {section.path()});
}

// ------------------------------------------------------------------------------ reference
namespace {

std::string escape(std::string s) {
  std::string out;
  for (char c : s) {
    if (c == '|')
      out += "\\|";
    else
      out += c;
  }
  return out;
}

std::string constraint_text(const Key& k, const std::string& path) {
  std::vector<std::string> parts;
  if (k.type == Type::Enum) {
    std::vector<std::string> quoted;
    for (const auto& a : k.allowed) quoted.push_back("`" + a + "`");
    parts.push_back(join(quoted, ", "));
  } else if (!k.allowed.empty()) {
    std::vector<std::string> quoted;
    for (const auto& a : k.allowed) quoted.push_back("`" + a + "`");
    parts.push_back(join(quoted, " or "));
  }
  if (const auto r = range_text(k); !r.empty()) parts.push_back(r == "positive" ? "> 0" : r);
  if (k.size) parts.push_back(fmt::format("{} entries", k.size));
  for (const auto& c : k.when) {
    const std::string key = c.key.find('.') == std::string::npos ? (path.empty() ? c.key : path + "." + c.key) : c.key;
    parts.push_back(c.values.empty() ? "only with `" + key + "`"
                                     : "only when `" + key + "` is " + join(c.values, " or "));
  }
  if (!k.one_of.empty()) parts.push_back("exactly one of its group");
  return join(parts, "; ");
}

void table(std::ostringstream& out, const std::vector<Key>& keys, const std::string& path,
           std::vector<std::pair<std::string, const Key*>>& nested) {
  out << "| key | type | required | default | unit | allowed | meaning |\n";
  out << "|---|---|---|---|---|---|---|\n";
  for (const auto& k : keys) {
    const std::string key = path + "." + k.name;
    std::string required = k.required ? (k.when.empty() ? "yes" : "yes (when used)") : "";
    std::string type = short_type(k.type);
    if (k.type == Type::NamedMap) type = std::string("map of ") + short_type(k.children.front().type);
    std::string meaning = k.meaning;
    if ((k.type == Type::Section || k.type == Type::SectionList) && !k.children.empty()) {
      meaning += " (below)";
      nested.push_back({key, &k});
    }
    std::string unit = k.type == Type::NamedMap ? k.children.front().unit : k.unit;
    out << "| `" << key << "` | " << escape(type) << " | " << required << " | "
        << (k.default_value.empty() ? "" : "`" + escape(k.default_value) + "`") << " | " << escape(unit) << " | "
        << escape(constraint_text(k, path)) << " | " << escape(meaning) << " |\n";
  }
}

void keys_with_nested(std::ostringstream& out, const std::vector<Key>& keys, const std::string& path) {
  std::vector<std::pair<std::string, const Key*>> nested;
  table(out, keys, path, nested);
  for (const auto& [key, k] : nested) {
    out << "\n`" << key << (k->type == Type::SectionList ? "[i]" : "") << "`: " << k->meaning
        << (k->type == Type::SectionList ? ", each item with" : "") << "\n\n";
    keys_with_nested(out, k->children, key + (k->type == Type::SectionList ? "[i]" : ""));
  }
}

}  // namespace

std::string reference_markdown() {
  const std::vector<Key> keys = scene_keys();
  std::ostringstream out;
  out << "# Scene reference\n\n"
      << "<!-- Generated from the scene-key declarations (each component's *_keys.cpp) by\n"
      << "     `build/bin/fsi check --reference > docs/scene-reference.md`; do not edit by hand. -->\n\n"
      << "Every key a scene file (`configs/*.yaml`) may hold, per section and, for `solid` and\n"
      << "`fluid`, per `model`. `fsi check SCENE [--set key=value ...]` checks a scene against this\n"
      << "list without meshing or starting a process (`fsi run` does it first): an unknown key, a\n"
      << "missing required key, a wrong type or a value out of range is reported as\n"
      << "`file:line:column: message`, with the closest known key for a typo.\n\n"
      << "Types: `number` (finite), `integer`, `bool` (`true`/`false`), `string`, `enum` (one of the\n"
      << "listed words), `[x, y]` (a list of two numbers), `section` (a map of the keys listed below\n"
      << "it), `list of sections`, `map` (names you choose, each with a value of the given type).\n"
      << "An optional key left empty (`key:`) takes its default.\n\n";
  out << "## Top level\n\n";
  {
    std::vector<std::pair<std::string, const Key*>> nested;
    out << "| key | type | required | meaning |\n|---|---|---|---|\n";
    for (const auto& k : keys) {
      std::string meaning = k.meaning;
      if (k.name == "coupling") meaning += "; without it the scene has exactly one of `solid`, `fluid`";
      out << "| `" << k.name << "` | " << short_type(k.type) << " | " << (k.required ? "yes" : "") << " | "
          << escape(meaning) << " |\n";
    }
  }
  for (const auto& k : keys) {
    if (k.type != Type::Section) continue;
    if (k.selector.empty()) {
      out << "\n## " << k.name << "\n\n" << k.meaning << ".\n\n";
      keys_with_nested(out, k.children, k.name);
      continue;
    }
    out << "\n## " << k.name << "\n\n"
        << k.meaning << ". `" << k.name << "." << k.selector
        << "` (required) selects the model; each model takes the keys of its table.\n";
    for (const auto& v : k.variants) {
      out << "\n### " << k.name << "." << k.selector << ": " << v.value << "\n\n" << v.meaning << ".\n\n";
      keys_with_nested(out, v.keys, k.name);
    }
  }
  out << "\n## Rules between keys\n\n"
      << "- `time.end` is a whole number of time steps `time.dt`.\n"
      << "- `coupling.relaxation` is below 2 with `coupling.algorithm: 1`.\n"
      << "- A scene with `coupling` has `solid` and `fluid`; one without has exactly one of them.\n"
      << "- The names of meshes' groups, edge sets and files are checked when the solver reads the mesh.\n";
  return out.str();
}

}  // namespace fsi::schema
