// Reading a scene section through its declaration (scene_reader.hpp).
#include "fsi/common/scene_reader.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

namespace fsi::schema {

namespace detail {

YAML::Node parse_default(const Key& k, const std::string& where) {
  try {
    return YAML::Load(k.default_value);
  } catch (const YAML::Exception&) {
    misuse(where, "its declared default '" + k.default_value + "' is not YAML");
  }
}

void misuse(const std::string& where, const std::string& message) {
  throw std::logic_error("scene key '" + where + "' " + message);
}

std::string one_of(const std::vector<std::string>& values) {
  std::string out;
  for (std::size_t i = 0; i < values.size(); ++i) {
    if (i > 0) out += i + 1 == values.size() ? " or " : ", ";
    out += "'" + values[i] + "'";
  }
  return out;
}

}  // namespace detail

namespace {

const std::vector<Key>& children_of(const Key& k) {
  if (k.type != Type::Section && k.type != Type::SectionList) detail::misuse(k.name, "is not a section");
  return k.children;
}

}  // namespace

Reader::Reader(ConfigSection section, const std::vector<Key>& declared)
    : section_(std::move(section)), keys_(&declared) {}

Reader::Reader(ConfigSection section, const Key& declaration)
    : section_(std::move(section)), keys_(&children_of(declaration)) {}

const Key& Reader::declared(const std::string& name) const {
  const auto k = std::find_if(keys_->begin(), keys_->end(), [&](const Key& x) { return x.name == name; });
  if (k == keys_->end()) detail::misuse(section_.full_key(name), "is read but not declared");
  return *k;
}

bool Reader::given(const std::string& name) const { return section_.given(name); }

bool Reader::has(const std::string& name) const {
  (void)declared(name);
  return section_.has(name);
}

std::array<double, 2> Reader::vector2(const std::string& name) const {
  const Key& k = declared(name);
  if (given(name)) return read_vector2(section_, name);
  if (k.type == Type::NumberOrVector2 && !k.computed_default && !k.default_value.empty() &&
      k.default_value.front() != '[')
    return {declared_default<double>(k), 0.0};
  const auto v = declared_default<std::vector<double>>(k);
  if (v.size() != 2) detail::misuse(section_.full_key(name), "its declared default is not [x, y]");
  return {v[0], v[1]};
}

std::vector<double> Reader::vector(const std::string& name, int dim) const {
  const Key& k = declared(name);
  if (k.type != Type::Vector && k.type != Type::NumberOrVector)
    detail::misuse(section_.full_key(name), "is read as a vector but not declared as one");
  std::vector<double> v;
  if (given(name)) {
    if (section_.node_is_scalar(name)) {
      if (k.type != Type::NumberOrVector) fail(name, fmt::format("must be a list of {} numbers", dim));
      v = {section_.get<double>(name)};
    } else {
      v = section_.get<std::vector<double>>(name);
      if (static_cast<int>(v.size()) != dim)
        fail(name, fmt::format("has {} components, but the model is {}D: give {}", v.size(), dim,
                               dim == 2 ? "[x, y]" : "[x, y, z]"));
    }
    for (double x : v)
      if (!std::isfinite(x)) fail(name, "must be finite");
  } else if (!k.computed_default && !k.default_value.empty() && k.default_value.front() != '[') {
    v = {declared_default<double>(k)};
  } else {
    v = declared_default<std::vector<double>>(k);
    if (static_cast<int>(v.size()) != dim)
      detail::misuse(section_.full_key(name), "its declared default has the wrong number of components");
  }
  v.resize(static_cast<std::size_t>(dim), 0.0);
  return v;
}

std::vector<std::string> Reader::names(const std::string& name) const {
  const Key& k = declared(name);
  if (given(name)) {
    if (section_.node_is_scalar(name)) return {section_.get<std::string>(name)};
    return section_.get<std::vector<std::string>>(name);
  }
  if (k.default_value == "none") return {};
  return declared_default<std::vector<std::string>>(k);
}

std::filesystem::path Reader::path(const std::string& name) const {
  (void)declared(name);
  return section_.get_path(name);
}

Reader Reader::child(const std::string& name) const { return Reader(section_.child(name), declared(name)); }

std::optional<Reader> Reader::optional_child(const std::string& name) const {
  const Key& k = declared(name);
  auto c = section_.optional_child(name);
  if (!c) return std::nullopt;
  return Reader(*c, k);
}

Reader Reader::child_or_defaults(const std::string& name) const {
  return Reader(section_.child_or_empty(name), declared(name));
}

std::vector<Reader> Reader::list(const std::string& name) const {
  const Key& k = declared(name);
  std::vector<Reader> out;
  for (auto& s : section_.list(name)) out.emplace_back(s, k);
  return out;
}

}  // namespace fsi::schema
