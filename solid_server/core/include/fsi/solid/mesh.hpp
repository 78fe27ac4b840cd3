#pragma once
// Solid meshes of either dimension: Q4 cells in 2D, Hex8 cells in 3D, and named facet sets
// (boundary edges in 2D, boundary quadrilaterals in 3D) for clamps, supports, interfaces
// and loads.
#include <Eigen/Core>
#include <array>
#include <map>
#include <string>
#include <vector>

namespace fsi {
struct GmshMesh;
}

namespace fsi::solid {

using Facet = std::vector<int>;  // 2 nodes (2D edge) or 4 nodes (3D quadrilateral face)

struct SolidMesh {
  int dim = 2;                                           // 2: plane strain Q4; 3: Hex8
  Eigen::MatrixXd nodes;                                 // reference coordinates, n x dim
  std::vector<std::vector<int>> cells;                   // counter-clockwise Q4, or Hex8 (element.hpp's order)
  std::map<std::string, std::vector<Facet>> facet_sets;  // boundary facets by name

  int num_nodes() const { return static_cast<int>(nodes.rows()); }
  int num_cells() const { return static_cast<int>(cells.size()); }
  int nodes_per_cell() const { return dim == 2 ? 4 : 8; }
  // Facets of the named sets (throws std::invalid_argument listing the known names).
  std::vector<Facet> facets(const std::vector<std::string>& names) const;
  // Unique node ids of the named sets, in order of first appearance.
  std::vector<int> facet_nodes(const std::vector<std::string>& names) const;
  std::vector<std::string> facet_set_names() const;
};

// The facets without repeats (a facet in two named sets, or listed twice, counted once), in
// order of first appearance.
std::vector<Facet> unique_facets(const std::vector<Facet>& facets);

// int N_a n0 dA of each node a of each facet (f.size() x dim per facet), n0 the outward normal
// of the reference configuration: oriented away from the cell that holds the facet, whatever
// the facet's node order. Throws std::invalid_argument for a facet that is no cell's side.
std::vector<Eigen::MatrixXd> outward_area_vectors(const SolidMesh& mesh, const std::vector<Facet>& facets);

// Structured nx x ny Q4 mesh of [x0, x0+lx] x [y0, y0+ly]; edge sets "left", "right",
// "bottom", "top". Node (i, j) has id j * (nx + 1) + i.
SolidMesh rectangle_mesh(double x0, double y0, double lx, double ly, int nx, int ny);

// Structured nx x ny x nz Hex8 mesh of the box origin + [0, size]; face sets "left" (x min),
// "right" (x max), "bottom" (y min), "top" (y max), "back" (z min), "front" (z max), each
// face's nodes counter-clockwise seen from outside. Node (i, j, k) has id
// (k * (ny + 1) + j) * (nx + 1) + i.
SolidMesh box_mesh(const Eigen::Vector3d& origin, const Eigen::Vector3d& size, int nx, int ny, int nz);

// Structured Hex8 tube (a thick-walled cylinder) around the axis through `origin` along +z:
// radii [r_inner, r_outer], length `length`, n_theta cells around, n_r through the wall, n_z
// along. Face sets "inner" (r = r_inner), "outer", "start" (z = origin z), "end"; each face's
// nodes counter-clockwise seen from outside the solid. Node (i, j, k) (i radial, j around, k
// along; j periodic) has id (k * n_theta + j) * (n_r + 1) + i.
SolidMesh tube_mesh(const Eigen::Vector3d& origin, double r_inner, double r_outer, double length, int n_theta, int n_r,
                    int n_z);

// Moves interior nodes of a mesh by a smooth-free random-like but deterministic
// perturbation of up to `fraction` of the local spacing (for patch tests).
void distort_interior(SolidMesh& mesh, double fraction, unsigned seed = 1);

// Converts a gmsh mesh (2D): every 2D group of quad4 cells (or only `domain` when non-empty)
// becomes the cells, every 1D group of 2-node lines an edge set of the same name. Unused
// nodes are dropped; clockwise cells are reordered. Throws std::invalid_argument on
// unsupported cell types.
SolidMesh mesh_from_gmsh(const GmshMesh& gmsh, const std::string& domain = "");

}  // namespace fsi::solid
