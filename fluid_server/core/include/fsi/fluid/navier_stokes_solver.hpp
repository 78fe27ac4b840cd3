#pragma once
// The P1/P1 SUPG/PSPG/LSIC Navier-Stokes solver (the seed paper's element): FlowSolver
// (flow_solver.hpp) with fluid.element p1p1 on a mesh of 3-node triangles. Unknowns (u, v, p)
// per node at 3 i, 3 i + 1, 3 i + 2; element kernel in p1_element.hpp.
//
//   NavierStokesSolver solver(mesh, params);
//   solver.add_dirichlet("inlet", profile);  ...  solver.set_interface({"flag"});
//   for each step: solver.solve(t, dt, positions, interface_velocity); solver.accept();
#include "fsi/fluid/flow_solver.hpp"
#include "fsi/fluid/p1_element.hpp"

namespace fsi::fluid {

class NavierStokesSolver : public FlowSolver {
 public:
  NavierStokesSolver(FluidMesh mesh, FlowParameters params) : FlowSolver(std::move(mesh), params, "p1p1") {}
};

}  // namespace fsi::fluid
