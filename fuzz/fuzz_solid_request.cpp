// libFuzzer target: a sequence of fsi.v1.Request messages -> one fresh SolidService built as
// solid_server builds it (fsi::models::make_solid_model: `sdof` and the finite-element
// solid `fem`). Input format and oracle: request_harness.hpp.
//
// Limits (a Configure beyond them is not sent): `fem` only on a `rectangle` mesh (a `gmsh`
// mesh would read a file named by the input) of at most 64 cells, load_steps <= 4,
// newton.max_iterations <= 20, at most 8 probes / tractions / point loads.
#include "fsi/models/solid_factory.hpp"
#include "request_harness.hpp"

namespace {

bool admit(const fsi::v1::Configure& c) {
  using namespace fsi_fuzz;
  const YAML::Node s = configured_section(c, "solid");
  if (!s || !s.IsMap()) return true;  // the service refuses it
  if (scalar(lookup(s, "model")) != "fem") return true;
  const YAML::Node mesh = lookup(s, "mesh");
  if (mesh && mesh.IsMap()) {
    const YAML::Node type = lookup(mesh, "type");
    if (type && scalar(type) != "rectangle") return false;
    const YAML::Node elements = lookup(mesh, "elements");
    try {
      if (elements) {
        const auto n = elements.as<std::vector<int>>();
        long long cells = 1;
        for (int k : n) cells *= k < 1 ? 1 : (k > 100000 ? 100000 : k);
        if (cells > 64) return false;
      }
    } catch (...) {
    }
  }
  if (as_int(lookup(s, "load_steps"), 1) > 4) return false;
  const YAML::Node newton = lookup(s, "newton");
  if (newton && newton.IsMap() && as_int(lookup(newton, "max_iterations"), 1) > 20) return false;
  for (const char* key : {"probes", "tractions", "point_loads"})
    if (list_size(lookup(s, key)) > 8) return false;
  return true;
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  fsi_fuzz::quiet_logs();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  fsi::protocol::SolidService service(fsi::models::make_solid_model, "fuzz solid_server");
  return fsi_fuzz::run_requests(service, data, size, admit);
}
