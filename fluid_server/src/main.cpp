// fluid_server: hosts a fluid model behind the wire protocol (proto/), or runs a scene's
// fluid alone.
//
// Sample runs:
//   fluid_server --bind tcp://0.0.0.0:5556                 # serve a coupler on another host
//   fluid_server --bind 'tcp://127.0.0.1:*' --port-file p  # free port, written to p
//   fluid_server --standalone configs/dfg_2d1.yaml --out runs/dfg_2d1
#include "fsi/common/standalone.hpp"
#include "fsi/models/fluid_factory.hpp"
#include "fsi/protocol/server_main.hpp"

int main(int argc, char** argv) {
  return fsi::protocol::server_main(argc, argv,
                                    {"fluid",
                                     [](const fsi::Scene& scene, const std::string& out) {
                                       return fsi::run_standalone_fluid(fsi::models::make_fluid_model, scene, out);
                                     },
                                     [] {
                                       return std::make_unique<fsi::protocol::FluidService>(
                                           fsi::models::make_fluid_model, "fsi fluid_server 0.1");
                                     }});
}
