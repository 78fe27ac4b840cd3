#pragma once
// The fluid's VTK grid (fluid.output, NavierStokesFluid::write_output) for both dimensions: the
// solver's current node positions, its cells and the point data velocity, pressure and
// mesh_displacement (current minus reference positions). The cells are the dimension's part:
//  - 2D: linear triangles (a 6-node triangle as its 4 linear sub-triangles on the same nodes);
//  - 3D: VTK_QUADRATIC_TETRA (24) for 10-node tetrahedra (VTK's edge order 01, 12, 20, 03, 13,
//    23 from gmsh's 01, 12, 20, 30, 32, 31), VTK_TETRA (10) for 4-node ones.
#include "fsi/common/vtk_writer.hpp"
#include "fsi/fluid/flow_solver.hpp"

namespace fsi::fluid {

template <int Dim>
VtkGrid flow_vtk_grid(const BasicFlowSolver<Dim>& solver);

}  // namespace fsi::fluid
