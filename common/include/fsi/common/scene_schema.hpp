#pragma once
// The scene schema: every key of every section (time, coupling, solid, fluid and the keys of
// each solver model), with its type, default, unit, allowed values, meaning and whether it is
// required. Each key is declared once, beside the code that reads it (time: standalone.cpp;
// coupling: coupler/src/coupling_keys.cpp; solid and fluid: each model's *_keys.cpp), and read
// through that declaration (scene_reader.hpp), so its name, default and range are written in
// one place. A component declares its section with `declare()`; the declarations are the
// single source of truth for
//   - `fsi check SCENE` (and `fsi run`, which checks first): every key validated without
//     meshing or starting a process;
//   - the servers and the coupler, which validate their section against it before they build
//     anything (the readers' own check_all_used() stays as the backstop);
//   - docs/scene-reference.md (`fsi check --reference`).
//
// A solver section's keys depend on its `model` (solid: sdof, fem; fluid: surrogate, fem);
// some keys depend on another key (fluid.element, solid.mesh.type, ...): `when` below.
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "fsi/common/config.hpp"

namespace fsi::detail {
// "a.b.c" -> {"a", "b", "c"} (config.cpp).
std::vector<std::string> split_dotted(const std::string& key);
}  // namespace fsi::detail

namespace fsi::schema {

enum class Type {
  Number,           // a finite number
  Integer,          // a whole number
  Bool,             // true / false
  String,           // any text
  Enum,             // one of `allowed`
  Vector2,          // [x, y]
  NumberOrVector2,  // x (y = 0) or [x, y]
  Vector,           // [x, y] or [x, y, z]: as many components as the model's dimension
  NumberOrVector,   // x (the other components 0), [x, y] or [x, y, z]
  Names,            // a name or a list of names
  StringList,       // a list of names
  IntList,          // a list of `size` integers
  PointPair,        // [[x0, y0], [x1, y1]]
  Section,          // a map of the `children` keys
  SectionList,      // a list of maps of the `children` keys
  NamedMap,         // a map from names the user chooses to values of children[0]
};

// A key is used only when another key has one of `values` (empty: when it is given at all).
// `key` without a dot names a key of the same map, with dots a key from the scene's root.
struct Condition {
  std::string key;
  std::vector<std::string> values;
  std::string fallback;  // the other key's value when it is absent
};

struct Key;

// One value of a selector key (solid.model: sdof | fem) and the keys it brings. Declared before
// Key and holding a vector of the then incomplete Key, which the standard allows (a vector of an
// incomplete type must be complete before use); the other way round, clang rejects Key's inline
// members.
struct KeyVariant {
  std::string value;    // e.g. "fem"
  std::string meaning;  // one line for the reference
  std::vector<Key> keys;
};

struct Key {
  std::string name;
  Type type = Type::Number;
  bool required = false;
  std::string default_value;  // as documented ("" = none)
  std::string unit;
  std::string meaning;
  std::vector<std::string> allowed;  // Enum; Number/Integer: the only values allowed
  std::optional<double> lo, hi;
  bool lo_open = false, hi_open = false;
  std::string range_message;  // instead of "must be > 0" etc., e.g. "(beta) must be > 0"
  std::string one_of;         // exactly one key of the same group (in the same map) must be given
  std::vector<Condition> when;
  std::vector<Key> children;  // Section, SectionList; NamedMap: one entry, the value
  int size = 0;               // IntList, StringList: the number of entries (0 = any)
  // Sections whose keys depend on one of their keys (solid.model): that key and its variants.
  std::string selector;
  using Variant = KeyVariant;
  std::vector<Variant> variants;
  // A top-level section's rules between keys: its reader, run on a scene whose section passed
  // the key-by-key checks (throws ConfigError).
  std::function<void(const Scene&)> check;

  // The default depends on other keys (e.g. "8 (iqn-ils), 0 (iqn-imvj)"): `default_value` only
  // documents it, and the reader computes it (Reader::get_or).
  bool computed_default = false;

  Key& req() {
    required = true;
    return *this;
  }
  Key& def(std::string d) {
    default_value = std::move(d);
    return *this;
  }
  Key& def_computed(std::string d) {
    default_value = std::move(d);
    computed_default = true;
    return *this;
  }
  Key& in_unit(std::string u) {
    unit = std::move(u);
    return *this;
  }
  Key& values(std::vector<std::string> v) {
    allowed = std::move(v);
    return *this;
  }
  Key& gt(double v) {
    lo = v;
    lo_open = true;
    return *this;
  }
  Key& ge(double v) {
    lo = v;
    lo_open = false;
    return *this;
  }
  Key& lt(double v) {
    hi = v;
    hi_open = true;
    return *this;
  }
  Key& le(double v) {
    hi = v;
    hi_open = false;
    return *this;
  }
  Key& says(std::string m) {
    range_message = std::move(m);
    return *this;
  }
  Key& group(std::string g) {
    one_of = std::move(g);
    return *this;
  }
  Key& only_when(std::string key, std::vector<std::string> vals = {}, std::string fallback = "") {
    when.push_back({std::move(key), std::move(vals), std::move(fallback)});
    return *this;
  }
  Key& with(std::vector<Key> c) {
    children = std::move(c);
    return *this;
  }
  Key& count(int n) {
    size = n;
    return *this;
  }
};

// Building declarations.
Key number(std::string name, std::string meaning);
Key integer(std::string name, std::string meaning);
Key boolean(std::string name, std::string meaning);
Key text(std::string name, std::string meaning);
Key choice(std::string name, std::vector<std::string> values, std::string meaning);
Key vector2(std::string name, std::string meaning);
Key number_or_vector2(std::string name, std::string meaning);
Key vector(std::string name, std::string meaning);            // 2 or 3 components (Reader::vector)
Key number_or_vector(std::string name, std::string meaning);  // a number or 2 or 3 components
Key names(std::string name, std::string meaning);
Key string_list(std::string name, std::string meaning);
Key int_list(std::string name, int size, std::string meaning);
Key point_pair(std::string name, std::string meaning);
Key section(std::string name, std::string meaning, std::vector<Key> children);
Key section_list(std::string name, std::string meaning, std::vector<Key> children);
Key named_map(std::string name, std::string meaning, Key value);
// A section whose keys depend on its `selector` key (solid.model: sdof | fem).
Key selector_section(std::string name, std::string meaning, std::string selector, std::vector<KeyVariant> variants);

// Declares a top-level section (coupling, solid, fluid); replaces one of the same name. The
// components' declaration functions call it, so a program knows the sections it reads; the
// launcher declares every section.
void declare(const Key& section);

// The scene's top-level keys: scene, description, time, then the declared sections (coupling,
// solid, fluid first, in that order).
std::vector<Key> scene_keys();

struct Problem {
  std::string where;  // "file:line:col", "file (--set key=value)", or "" when in message
  std::string message;
  std::string key;  // dotted key the problem is about ("" = the scene)
  std::string text() const { return where.empty() ? message : where + ": " + message; }
};

struct CheckOptions {
  // Sections not checked (e.g. "solid" when an external solid, with keys of its own, is used).
  std::vector<std::string> skip_sections;
  // Check only these top-level sections ("" entries ignored; empty = every section).
  std::vector<std::string> only_sections;
  // Where an override came from, when not from the command line: "key=value" -> "file:line:col".
  std::vector<std::pair<std::string, std::string>> override_origins;
};

struct CheckResult {
  std::vector<Problem> problems;
  int keys_checked = 0;
  bool ok() const { return problems.empty(); }
};

// Every problem of the scene (unknown keys with a suggestion, missing required keys, wrong
// types, values out of range, keys of another model or element), in file order per section.
CheckResult check_scene(const Scene& scene, const CheckOptions& options = {});

// Throws one ConfigError listing every problem of the section(s) (for the servers and the
// coupler, before they build anything). Does nothing for a section name the schema does not
// know (a server started for another section name).
void require_valid(const Scene& scene, const std::vector<std::string>& sections);
// The same for the scene section a solver server is about to configure; a `model` the schema
// does not know is left to the server's factory.
void require_valid(const ConfigSection& section);

// "" when `value` is allowed by the key's values or range, else what it must be ("must be > 0",
// or the key's own range message).
std::string range_problem(const Key& k, double value);

// docs/scene-reference.md.
std::string reference_markdown();

// Levenshtein distance; and the closest of `candidates` to `word` if close enough ("" = none).
std::size_t edit_distance(const std::string& a, const std::string& b);
std::string closest(const std::string& word, const std::vector<std::string>& candidates);

}  // namespace fsi::schema
