// The keys of `solid.model: sdof`, declared once beside their reader (sdof_solid.cpp).
#include "fsi/common/scene_schema.hpp"
#include "fsi/models/sdof_solid.hpp"

namespace fsi::models {

const std::vector<schema::Key>& sdof_solid_keys() {
  using namespace schema;
  static const std::vector<Key> keys = [] {
    std::vector<Key> k = {
        number("mass", "m").req().gt(0).in_unit("kg"),
        number("damping", "c").def("0").ge(0).in_unit("N s/m"),
        number("stiffness", "k").def("0").ge(0).in_unit("N/m"),
        number("interface_measure", "M_G: Algorithm 2 adds m_fs = gamma_N1 * measure").def("1").gt(0),
        number_or_vector("force", "external force on the solid itself").def("0").in_unit("N"),
        number_or_vector("initial_displacement", "d_0").def("0").in_unit("m"),
        number_or_vector("initial_velocity", "v_0").def("0").in_unit("m/s"),
    };
    for (auto& key : model_interface_keys()) k.push_back(std::move(key));
    return k;
  }();
  return keys;
}

}  // namespace fsi::models
