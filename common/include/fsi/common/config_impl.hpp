#pragma once
// Template definitions for config.hpp (not a public header).
#include <cmath>
#include <type_traits>

namespace fsi::detail {
template <class T>
constexpr const char* type_name() {
  if constexpr (std::is_same_v<T, bool>)
    return "a boolean (true/false)";
  else if constexpr (std::is_integral_v<T>)
    return "an integer";
  else if constexpr (std::is_floating_point_v<T>)
    return "a number";
  else if constexpr (std::is_same_v<T, std::string>)
    return "a string";
  else
    return "a list";
}
}  // namespace fsi::detail

namespace fsi {

template <class T>
T ConfigSection::convert(const std::string& key, const YAML::Node& value) const {
  try {
    if constexpr (std::is_same_v<T, std::string>) {
      if (!value.IsScalar()) throw YAML::Exception(value.Mark(), "not a scalar");
      return value.Scalar();
    } else if constexpr (std::is_floating_point_v<T>) {
      if (!value.IsScalar()) throw YAML::Exception(value.Mark(), "not a scalar");
      T v = value.as<T>();
      if (!std::isfinite(v)) fail(key, "must be a finite number, got '" + value.Scalar() + "'");
      return v;
    } else {
      return value.as<T>();
    }
  } catch (const YAML::Exception&) {
    fail(key, std::string("must be ") + detail::type_name<T>() + ", got '" +
                  (value.IsScalar() ? value.Scalar() : std::string("a non-scalar value")) + "'");
  }
}

template <class T>
T ConfigSection::get(const std::string& key) const {
  YAML::Node value = lookup(key);
  if (!value) fail(key, "is required but missing");
  return convert<T>(key, value);
}

template <class T>
T ConfigSection::get(const std::string& key, const T& fallback) const {
  YAML::Node value = lookup(key);
  if (!value || value.IsNull()) return fallback;
  return convert<T>(key, value);
}

}  // namespace fsi
