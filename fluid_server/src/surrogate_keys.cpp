// The keys of `fluid.model: surrogate`, declared once beside their reader (surrogate_fluid.cpp).
#include "fsi/common/scene_schema.hpp"
#include "fsi/models/surrogate_fluid.hpp"

namespace fsi::models {

const std::vector<schema::Key>& surrogate_fluid_keys() {
  using namespace schema;
  static const std::vector<Key> keys = {
      number_or_vector2("force", "F, the constant fluid force on the solid").def("0").in_unit("N"),
      number("added_mass", "m_a: the force is F - m_a a").def("0").ge(0).in_unit("kg"),
      number("interface_measure", "M_G of the point interface").def("1").gt(0),
  };
  return keys;
}

}  // namespace fsi::models
