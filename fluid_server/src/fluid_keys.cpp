// The `fluid` section: one table of keys per model this server hosts, each declared beside
// its model's reader (surrogate_keys.cpp, core/src/navier_stokes_keys.cpp).
#include "fsi/common/waveform.hpp"
#include "fsi/models/fluid_factory.hpp"
#include "fsi/models/surrogate_fluid.hpp"
#ifdef FSI_HAVE_FEM_FLUID
#include "fsi/fluid/navier_stokes_fluid.hpp"
#endif

namespace fsi::models {

const schema::Key& fluid_section() {
  static const schema::Key fluid = [] {
    std::vector<schema::KeyVariant> models{
        {"surrogate", "constant force with an added mass at one point", surrogate_fluid_keys()}};
#ifdef FSI_HAVE_FEM_FLUID
    models.push_back({"fem", "incompressible Navier-Stokes on a moving (ALE) mesh, P1/P1 or P2/P1",
                      fsi::fluid::navier_stokes_keys()});
#endif
    // Every model takes `substeps` (waveform iterations; the coupler reads it).
    for (auto& model : models)
      for (auto& key : window_keys()) model.keys.push_back(std::move(key));
    schema::Key k = schema::selector_section("fluid", "the fluid solver (fluid_server)", "model", std::move(models));
    schema::declare(k);
    return k;
  }();
  return fluid;
}

}  // namespace fsi::models
