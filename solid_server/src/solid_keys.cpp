// The `solid` section: one table of keys per model this server hosts, each declared beside
// its model's reader (sdof_keys.cpp, core/src/fem_solid_keys.cpp).
#include "fsi/common/waveform.hpp"
#include "fsi/models/sdof_solid.hpp"
#include "fsi/models/solid_factory.hpp"
#ifdef FSI_HAVE_FEM_SOLID
#include "fsi/solid/fem_solid.hpp"
#endif

namespace fsi::models {

const schema::Key& solid_section() {
  static const schema::Key solid = [] {
    std::vector<schema::KeyVariant> models{
        {"sdof", "single-degree-of-freedom point solid m a + c v + k d = F", sdof_solid_keys()}};
#ifdef FSI_HAVE_FEM_SOLID
    models.push_back(
        {"fem", "finite-strain Q4 solid (Saint Venant-Kirchhoff or neo-Hookean)", fsi::solid::fem_solid_keys()});
#endif
    // Every model takes `substeps` (waveform iterations; the coupler reads it).
    for (auto& model : models)
      for (auto& key : window_keys()) model.keys.push_back(std::move(key));
    schema::Key k = schema::selector_section("solid", "the solid solver (solid_server)", "model", std::move(models));
    schema::declare(k);
    return k;
  }();
  return solid;
}

}  // namespace fsi::models
