#pragma once
// Solid meshes: Q4 cells and named edge sets (for clamps, interfaces and loads).
#include <Eigen/Core>
#include <array>
#include <map>
#include <string>
#include <vector>

namespace fsi {
struct GmshMesh;
}

namespace fsi::solid {

struct SolidMesh {
  Eigen::MatrixX2d nodes;                                            // reference coordinates
  std::vector<std::array<int, 4>> cells;                             // counter-clockwise Q4
  std::map<std::string, std::vector<std::array<int, 2>>> edge_sets;  // boundary edges by name

  int num_nodes() const { return static_cast<int>(nodes.rows()); }
  int num_cells() const { return static_cast<int>(cells.size()); }
  // Edges of the named sets (throws std::invalid_argument listing the known names).
  std::vector<std::array<int, 2>> edges(const std::vector<std::string>& names) const;
  // Unique node ids of the named sets, in order of first appearance.
  std::vector<int> edge_nodes(const std::vector<std::string>& names) const;
  std::vector<std::string> edge_set_names() const;
};

// Structured nx x ny Q4 mesh of [x0, x0+lx] x [y0, y0+ly]; edge sets "left", "right",
// "bottom", "top". Node (i, j) has id j * (nx + 1) + i.
SolidMesh rectangle_mesh(double x0, double y0, double lx, double ly, int nx, int ny);

// Moves interior nodes of a mesh by a smooth-free random-like but deterministic
// perturbation of up to `fraction` of the local spacing (for patch tests).
void distort_interior(SolidMesh& mesh, double fraction, unsigned seed = 1);

// Converts a gmsh mesh: every 2D group of quad4 cells (or only `domain` when non-empty)
// becomes the cells, every 1D group of 2-node lines an edge set of the same name. Unused
// nodes are dropped; clockwise cells are reordered. Throws std::invalid_argument on
// unsupported cell types.
SolidMesh mesh_from_gmsh(const GmshMesh& gmsh, const std::string& domain = "");

}  // namespace fsi::solid
