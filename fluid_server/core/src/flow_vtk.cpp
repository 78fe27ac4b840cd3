#include "fsi/fluid/flow_vtk.hpp"

namespace fsi::fluid {
namespace {

void add_cells(const FluidMesh& solver_mesh, VtkGrid& grid) {
  const auto mesh = solver_mesh.linear_refinement();  // P2: 4 linear triangles per element
  for (int e = 0; e < mesh.triangle_count(); ++e) {
    grid.cells.push_back({mesh.triangles(e, 0), mesh.triangles(e, 1), mesh.triangles(e, 2)});
    grid.cell_types.push_back(VtkCellType::Triangle);
  }
}

void add_cells(const TetMesh& mesh, VtkGrid& grid) {
  // VTK's quadratic tetrahedron: the midpoints of 01, 12, 20, 03, 13, 23, i.e. gmsh's edges 0, 1,
  // 2, 3 (30), 5 (31), 4 (32).
  constexpr int kVtkEdge[6] = {0, 1, 2, 3, 5, 4};
  for (int e = 0; e < mesh.cell_count(); ++e) {
    std::vector<int> cell{mesh.tets(e, 0), mesh.tets(e, 1), mesh.tets(e, 2), mesh.tets(e, 3)};
    if (mesh.quadratic())
      for (int k : kVtkEdge) cell.push_back(mesh.edge_nodes(e, k));
    grid.cells.push_back(std::move(cell));
    grid.cell_types.push_back(mesh.quadratic() ? VtkCellType::QuadraticTetra : VtkCellType::Tetra);
  }
}

}  // namespace

template <int Dim>
VtkGrid flow_vtk_grid(const BasicFlowSolver<Dim>& solver) {
  VtkGrid grid;
  grid.points = solver.positions();
  add_cells(solver.mesh(), grid);
  grid.point_data["velocity"] = solver.velocity();
  grid.point_data["pressure"] = solver.pressure();
  grid.point_data["mesh_displacement"] = solver.positions() - solver.mesh().nodes;
  return grid;
}

template VtkGrid flow_vtk_grid<2>(const BasicFlowSolver<2>&);
template VtkGrid flow_vtk_grid<3>(const BasicFlowSolver<3>&);

}  // namespace fsi::fluid
