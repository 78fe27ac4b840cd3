// Building scene-key declarations, and the registry of the declared sections (scene_schema.hpp).
// The keys themselves are declared beside the code that reads them: time in standalone.cpp,
// coupling in coupler/src/coupling_keys.cpp, the solid and fluid models in their *_keys.cpp;
// docs/scene-reference.md is generated from them (`fsi check --reference`).
#include <algorithm>
#include <mutex>

#include "fsi/common/scene_schema.hpp"
#include "fsi/common/standalone.hpp"

namespace fsi::schema {
namespace {

Key make(std::string name, Type type, std::string meaning) {
  Key k;
  k.name = std::move(name);
  k.type = type;
  k.meaning = std::move(meaning);
  return k;
}

struct Registry {
  std::mutex mutex;
  std::vector<Key> sections;
};

Registry& registry() {
  static Registry r;
  return r;
}

}  // namespace

Key number(std::string n, std::string m) { return make(std::move(n), Type::Number, std::move(m)); }
Key integer(std::string n, std::string m) { return make(std::move(n), Type::Integer, std::move(m)); }
Key boolean(std::string n, std::string m) { return make(std::move(n), Type::Bool, std::move(m)); }
Key text(std::string n, std::string m) { return make(std::move(n), Type::String, std::move(m)); }
Key choice(std::string n, std::vector<std::string> values, std::string m) {
  Key k = make(std::move(n), Type::Enum, std::move(m));
  k.allowed = std::move(values);
  return k;
}
Key vector2(std::string n, std::string m) { return make(std::move(n), Type::Vector2, std::move(m)); }
Key number_or_vector2(std::string n, std::string m) { return make(std::move(n), Type::NumberOrVector2, std::move(m)); }
Key vector(std::string n, std::string m) { return make(std::move(n), Type::Vector, std::move(m)); }
Key number_or_vector(std::string n, std::string m) { return make(std::move(n), Type::NumberOrVector, std::move(m)); }
Key names(std::string n, std::string m) { return make(std::move(n), Type::Names, std::move(m)); }
Key string_list(std::string n, std::string m) { return make(std::move(n), Type::StringList, std::move(m)); }
Key int_list(std::string n, int size, std::string m) {
  return make(std::move(n), Type::IntList, std::move(m)).count(size);
}
Key point_pair(std::string n, std::string m) { return make(std::move(n), Type::PointPair, std::move(m)); }
Key section(std::string n, std::string m, std::vector<Key> children) {
  return make(std::move(n), Type::Section, std::move(m)).with(std::move(children));
}
Key section_list(std::string n, std::string m, std::vector<Key> children) {
  return make(std::move(n), Type::SectionList, std::move(m)).with(std::move(children));
}
Key named_map(std::string n, std::string m, Key value) {
  return make(std::move(n), Type::NamedMap, std::move(m)).with({std::move(value)});
}
Key selector_section(std::string n, std::string m, std::string selector, std::vector<KeyVariant> variants) {
  Key k = section(std::move(n), std::move(m), {});
  k.selector = std::move(selector);
  k.variants = std::move(variants);
  return k;
}

void declare(const Key& section) {
  auto& r = registry();
  std::lock_guard<std::mutex> lock(r.mutex);
  const auto same =
      std::find_if(r.sections.begin(), r.sections.end(), [&](const Key& k) { return k.name == section.name; });
  if (same != r.sections.end())
    *same = section;
  else
    r.sections.push_back(section);
}

std::vector<Key> scene_keys() {
  std::vector<Key> keys = {
      text("scene", "the scene's name"),
      text("description", "one line about the scene"),
      choice("units", {"SI", "CGS"},
             "the unit system of the scene's numbers, for the units in plot labels and tables only: the solvers "
             "take no unit system of their own (SI: m, kg, s, N, Pa; CGS: cm, g, s, dyn, dyn/cm^2)")
          .def("SI"),
      time_section(),
  };
  auto& r = registry();
  std::lock_guard<std::mutex> lock(r.mutex);
  for (const char* name : {"coupling", "solid", "fluid"})
    for (const auto& k : r.sections)
      if (k.name == name) keys.push_back(k);
  for (const auto& k : r.sections)
    if (k.name != "coupling" && k.name != "solid" && k.name != "fluid") keys.push_back(k);
  return keys;
}

}  // namespace fsi::schema
