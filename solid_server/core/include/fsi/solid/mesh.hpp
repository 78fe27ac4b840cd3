#pragma once
// Solid meshes of either dimension: Q4 cells in 2D, Hex8 or Tet10 cells in 3D, and named
// facet sets (boundary edges in 2D; boundary quadrilaterals of Hex8 meshes or 6-node
// triangles of Tet10 meshes in 3D) for clamps, supports, interfaces and loads.
#include <Eigen/Core>
#include <array>
#include <map>
#include <string>
#include <vector>

#include "fsi/solid/element.hpp"

namespace fsi {
struct GmshMesh;
}

namespace fsi::solid {

// 2 nodes (2D edge), 4 nodes (3D quadrilateral face of a Hex8 mesh) or 6 nodes (3D quadratic
// triangle of a Tet10 mesh, gmsh order: vertices, then the midpoints of 0-1, 1-2, 2-0)
using Facet = std::vector<int>;

// The cells' shape (element.hpp); every cell of a mesh has the same.
enum class CellKind { Quad4, Hex8, Tet10 };
const char* cell_kind_name(CellKind kind);  // "quadrilateral (Q4)", ...

struct SolidMesh {
  int dim = 2;                                           // 2: plane strain Q4; 3: Hex8 or Tet10
  CellKind cell = CellKind::Quad4;                       // Quad4 in 2D; Hex8 or Tet10 in 3D
  Eigen::MatrixXd nodes;                                 // reference coordinates, n x dim
  std::vector<std::vector<int>> cells;                   // counter-clockwise Q4, or Hex8 / Tet10 (element.hpp's order)
  std::map<std::string, std::vector<Facet>> facet_sets;  // boundary facets by name

  int num_nodes() const { return static_cast<int>(nodes.rows()); }
  int num_cells() const { return static_cast<int>(cells.size()); }
  int nodes_per_cell() const { return cell == CellKind::Quad4 ? 4 : cell == CellKind::Hex8 ? 8 : 10; }
  // Facets of the named sets (throws std::invalid_argument listing the known names).
  std::vector<Facet> facets(const std::vector<std::string>& names) const;
  // Unique node ids of the named sets, in order of first appearance.
  std::vector<int> facet_nodes(const std::vector<std::string>& names) const;
  std::vector<std::string> facet_set_names() const;
};

// Calls f(Quad4{}), f(Hex8{}) or f(Tet10{}) by the mesh's cell kind: loops over cells are
// written once, templated on the shape.
template <class F>
decltype(auto) with_shape(CellKind kind, F&& f) {
  if (kind == CellKind::Tet10) return f(Tet10{});
  if (kind == CellKind::Hex8) return f(Hex8{});
  return f(Quad4{});
}

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

// The box of box_mesh() with each of its nx x ny x nz cubes split into 6 Tet10 cells around
// its diagonal (Kuhn; conforming), straight edges; the same six face sets as 6-node
// triangles, right-handed outward. The vertices come first, numbered as box_mesh's nodes.
SolidMesh box_tet_mesh(const Eigen::Vector3d& origin, const Eigen::Vector3d& size, int nx, int ny, int nz);

// Moves interior nodes of a mesh by a smooth-free random-like but deterministic
// perturbation of up to `fraction` of the local spacing (for patch tests).
void distort_interior(SolidMesh& mesh, double fraction, unsigned seed = 1);

// Converts a gmsh mesh. 2D: every 2D group of quad4 cells (or only `domain` when non-empty)
// becomes the cells, every 1D group of 2-node lines an edge set of the same name; clockwise
// cells are reordered. 3D (a mesh with volume groups): every 3D group (or only `domain`) of
// 10-node tetrahedra (gmsh type 11) or of 8-node hexahedra (type 5) becomes the cells, every
// 2D group of 6-node triangles (type 9) or 4-node quadrilaterals (type 3) respectively a face
// set; tetrahedra of negative orientation are mirrored. Unused nodes are dropped. Throws
// std::invalid_argument naming the group (and cell) for unsupported types, a facet that is no
// cell's side, or a cell whose map has det J <= 0 at a Gauss point.
SolidMesh mesh_from_gmsh(const GmshMesh& gmsh, const std::string& domain = "");

}  // namespace fsi::solid
