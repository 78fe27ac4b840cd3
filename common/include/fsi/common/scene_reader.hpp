#pragma once
// Reading a scene section through its declaration (scene_schema.hpp): a key's default, and
// whether it is required, come from the one place it is declared. A reader that asks for a key
// its declaration lacks is a programming error (std::logic_error), found by any test that
// configures the component.
//
//   const auto& keys = coupling_keys();                 // the declaration, beside the reader
//   schema::Reader r(scene.section("coupling"), keys);
//   int k_max = r.child("iterations").get<int>("max");  // required: ConfigError if missing
//   double tol = r.child("iterations").get<double>("tolerance");  // absent: the declared default
#include <algorithm>
#include <array>
#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

#include "fsi/common/config.hpp"
#include "fsi/common/scene_schema.hpp"

namespace fsi::schema {

class Reader {
 public:
  // `declared`: the keys of this section (a Section's children, or a model variant's keys).
  Reader(ConfigSection section, const std::vector<Key>& declared);
  // A top-level section declared with declare() / a Key of type Section.
  Reader(ConfigSection section, const Key& declaration);

  bool has(const std::string& name) const;
  // The value, or the declared default when the key is absent (or empty); a required key that
  // is missing is a ConfigError naming it.
  template <class T>
  T get(const std::string& name) const;
  // For keys whose declared default depends on other keys (Key::computed_default), and optional
  // keys without a default: `fallback` when absent.
  template <class T>
  T get_or(const std::string& name, const T& fallback) const;
  // [x, y], or x (y = 0) for NumberOrVector2; absent: the declared default.
  std::array<double, 2> vector2(const std::string& name) const;
  // A Vector or NumberOrVector key with `dim` components (2 or 3): a number x gives
  // [x, 0(, 0)]; a list of another length is a ConfigError naming the dimension.
  std::vector<double> vector(const std::string& name, int dim) const;
  // A Names key: one name or a list; absent: the declared default ("none" = no names).
  std::vector<std::string> names(const std::string& name) const;
  std::filesystem::path path(const std::string& name) const;

  Reader child(const std::string& name) const;  // a required Section
  // A Section given in the scene, or nothing (its keys then take their defaults: see defaults()).
  std::optional<Reader> optional_child(const std::string& name) const;
  // The child if given, otherwise a reader over an empty map whose every key takes its default.
  Reader child_or_defaults(const std::string& name) const;
  std::vector<Reader> list(const std::string& name) const;  // a SectionList

  // The declaration of a key of this section.
  const Key& declared(const std::string& name) const;
  const ConfigSection& section() const { return section_; }
  const std::string& path() const { return section_.path(); }
  std::string where(const std::string& name) const { return section_.where(name); }
  std::vector<std::string> keys() const { return section_.keys(); }
  [[noreturn]] void fail(const std::string& name, const std::string& message) const { section_.fail(name, message); }

 private:
  bool given(const std::string& name) const;
  template <class T>
  T declared_default(const Key& k) const;
  template <class T>
  T checked(const std::string& name, const Key& k) const;  // the value, within the declared range
  ConfigSection section_;
  const std::vector<Key>* keys_;
};

// ---------------------------------------------------------------------------- templates
namespace detail {
YAML::Node parse_default(const Key& k, const std::string& where);
[[noreturn]] void misuse(const std::string& where, const std::string& message);
std::string one_of(const std::vector<std::string>& values);  // "'a', 'b' or 'c'"
}  // namespace detail

template <class T>
T Reader::declared_default(const Key& k) const {
  const std::string where = section_.full_key(k.name);
  if (k.computed_default)
    detail::misuse(where, "has a computed default (" + k.default_value + "): read it with get_or");
  if (k.default_value.empty()) {
    if (k.required) return section_.get<T>(k.name);  // ConfigError: required but missing
    detail::misuse(where, "is optional without a declared default: read it with get_or or check has()");
  }
  try {
    return detail::parse_default(k, where).template as<T>();
  } catch (const YAML::Exception&) {
    detail::misuse(where, "its declared default '" + k.default_value + "' is not of the type the reader reads");
  }
}

template <class T>
T Reader::checked(const std::string& name, const Key& k) const {
  const T value = section_.get<T>(name);
  if constexpr (std::is_arithmetic_v<T> && !std::is_same_v<T, bool>) {
    if (const auto problem = range_problem(k, static_cast<double>(value)); !problem.empty())
      section_.fail(name, problem);
  } else if constexpr (std::is_same_v<T, std::string>) {
    if (k.type == Type::Enum && std::find(k.allowed.begin(), k.allowed.end(), value) == k.allowed.end())
      section_.fail(name, "must be " + detail::one_of(k.allowed) + ", got '" + value + "'");
  }
  return value;
}

template <class T>
T Reader::get(const std::string& name) const {
  const Key& k = declared(name);
  if (!given(name)) return declared_default<T>(k);
  return checked<T>(name, k);
}

template <class T>
T Reader::get_or(const std::string& name, const T& fallback) const {
  const Key& k = declared(name);
  if (!k.computed_default && !k.default_value.empty())
    detail::misuse(section_.full_key(name), "has a declared default (" + k.default_value + "): read it with get");
  if (!given(name)) return fallback;
  return checked<T>(name, k);
}

}  // namespace fsi::schema
