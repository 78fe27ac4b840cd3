// solid_server: hosts a solid model behind the wire protocol (proto/), or runs a scene's
// solid alone.
//
// Sample runs:
//   solid_server --bind tcp://0.0.0.0:5555                 # serve a coupler on another host
//   solid_server --bind 'tcp://127.0.0.1:*' --port-file p  # free port, written to p
//   solid_server --standalone configs/csm1.yaml --out runs/csm1
#include "fsi/common/standalone.hpp"
#include "fsi/models/solid_factory.hpp"
#include "fsi/protocol/server_main.hpp"

int main(int argc, char** argv) {
  return fsi::protocol::server_main(argc, argv,
                                    {"solid",
                                     [](const fsi::Scene& scene, const std::string& out) {
                                       return fsi::run_standalone_solid(fsi::models::make_solid_model, scene, out);
                                     },
                                     [] {
                                       return std::make_unique<fsi::protocol::SolidService>(
                                           fsi::models::make_solid_model, "fsi solid_server 0.1");
                                     }});
}
