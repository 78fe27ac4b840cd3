// fluid_server: hosts a fluid model behind the wire protocol (proto/), or runs a scene's
// fluid alone.
//
// Sample runs:
//   fluid_server --bind tcp://0.0.0.0:5556                 # serve a coupler on another host
//   fluid_server --bind 'tcp://127.0.0.1:*' --port-file p  # free port, written to p
//   fluid_server --standalone configs/dfg_2d1.yaml --out runs/dfg_2d1
//   mpirun -n 2 fluid_server --standalone configs/dfg_3d1z.yaml --set fluid.ranks=2 ...  # PETSc on 2 ranks
#include "fsi/common/standalone.hpp"
#include "fsi/models/fluid_factory.hpp"
#include "fsi/protocol/server_main.hpp"
#if FSI_HAVE_FEM_FLUID
#include "fsi/fluid/linear_solver.hpp"
#endif

int main(int argc, char** argv) {
#if FSI_HAVE_FEM_FLUID
  // Under mpirun with several ranks (fluid.ranks): ranks 1.. serve rank 0's PETSc solves.
  if (const int code = fsi::fluid::start_mpi_ranks(); code >= 0) return code;
#endif
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
