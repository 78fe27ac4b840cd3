// The keys of `fluid.model: surrogate`, declared once beside their reader (surrogate_fluid.cpp).
#include "fsi/common/model_interface.hpp"
#include "fsi/common/scene_schema.hpp"
#include "fsi/models/surrogate_fluid.hpp"

namespace fsi::models {

const std::vector<schema::Key>& surrogate_fluid_keys() {
  using namespace schema;
  static const std::vector<Key> keys = [] {
    std::vector<Key> k = {
        number_or_vector("force", "F, the constant fluid force on the solid: x, or one value per dimension")
            .def("0")
            .in_unit("N"),
        number("added_mass", "m_a: the force is F - m_a a").def("0").ge(0).in_unit("kg"),
        number("interface_measure", "M_G of the point interface").def("1").gt(0),
    };
    for (auto& key : model_interface_keys()) k.push_back(std::move(key));
    return k;
  }();
  return keys;
}

}  // namespace fsi::models
