#include "fsi/models/solid_factory.hpp"

#include "fsi/models/sdof_solid.hpp"
#ifdef FSI_HAVE_FEM_SOLID
#include "fsi/solid/fem_solid.hpp"
#endif

namespace fsi::models {

std::unique_ptr<SolidModel> make_solid_model(const std::string& name) {
  if (name == "sdof") return std::make_unique<SdofSolid>();
#ifdef FSI_HAVE_FEM_SOLID
  if (name == "fem") return std::make_unique<fsi::solid::FemSolid>();
#endif
  return nullptr;
}

std::vector<std::string> solid_model_names() {
  std::vector<std::string> names{"sdof"};
#ifdef FSI_HAVE_FEM_SOLID
  names.push_back("fem");
#endif
  return names;
}

}  // namespace fsi::models
