// libFuzzer target: a sequence of fsi.v1.Request messages -> one fresh FluidService built as
// fluid_server builds it (fsi::models::make_fluid_model). Input format and oracle:
// request_harness.hpp.
//
// Only the `surrogate` fluid is configured: a Configure for `fem` (Navier-Stokes, which
// meshes with the gmsh executable or reads a mesh file) is not sent.
#include "fsi/models/fluid_factory.hpp"
#include "request_harness.hpp"

namespace {

bool admit(const fsi::v1::Configure& c) {
  const YAML::Node s = fsi_fuzz::configured_section(c, "fluid");
  if (!s || !s.IsMap()) return true;  // the service refuses it
  return fsi_fuzz::scalar(fsi_fuzz::lookup(s, "model")) != "fem";
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  fsi_fuzz::quiet_logs();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  fsi::protocol::FluidService service(fsi::models::make_fluid_model, "fuzz fluid_server");
  return fsi_fuzz::run_requests(service, data, size, admit);
}
