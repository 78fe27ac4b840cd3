#include "fsi/models/fluid_factory.hpp"

#include "fsi/models/surrogate_fluid.hpp"
#ifdef FSI_HAVE_FEM_FLUID
#include "fsi/fluid/navier_stokes_fluid.hpp"
#endif

namespace fsi::models {

std::unique_ptr<FluidModel> make_fluid_model(const std::string& name) {
  if (name == "surrogate") return std::make_unique<SurrogateFluid>();
#ifdef FSI_HAVE_FEM_FLUID
  if (name == "fem") return std::make_unique<fsi::fluid::NavierStokesFluid>();
#endif
  return nullptr;
}

std::vector<std::string> fluid_model_names() {
  std::vector<std::string> names{"surrogate"};
#ifdef FSI_HAVE_FEM_FLUID
  names.push_back("fem");
#endif
  return names;
}

}  // namespace fsi::models
