#pragma once
// The isoparametric Taylor-Hood P2/P1 Navier-Stokes solver: FlowSolver (flow_solver.hpp) with
// fluid.element p2p1 on a mesh of 6-node triangles (a linear mesh gets straight midpoints):
// an inf-sup stable element instead of PSPG, Newton or Picard linearisation, optional grad-div
// and SUPG, P2 traces on the Nitsche interface. Unknowns (u, v) at every node (vertices and
// midpoints) at 2 i, 2 i + 1, p at the vertices after them (2 n + i); element kernel in
// p2p1_element.hpp. Interface quantities live at every interface node.
//
//   TaylorHoodSolver solver(mesh, params);
//   solver.add_dirichlet("inlet", profile);  ...  solver.set_interface({"flag"});
//   for each step: solver.solve(t, dt, positions, interface_velocity); solver.accept();
#include "fsi/fluid/flow_solver.hpp"

namespace fsi::fluid {

class TaylorHoodSolver : public FlowSolver {
 public:
  TaylorHoodSolver(FluidMesh mesh, FlowParameters params) : FlowSolver(std::move(mesh), params, "p2p1") {}
};

}  // namespace fsi::fluid
