#pragma once
// The fluid's tetrahedral mesh (3D): linear (4-node) or quadratic (10-node) tetrahedra with
// positive volume, and named boundary groups of triangles. Built from a gmsh mesh (tet4/tet10
// with tri3/tri6 boundary faces) or (for tests) a structured box.
//
// Quadratic meshes (Taylor-Hood P2/P1): the vertices are nodes 0 .. vertex_count - 1, the edge
// midpoints (possibly curved: gmsh -order 2 puts them on the geometry) follow; `tets` holds the
// four vertices, `edge_nodes(e, k)` the node of edge k in gmsh's order
// (01, 12, 20, 30, 32, 31: kTetEdges), and every boundary face (a, b, c) has its three edge
// midpoints (ab, bc, ca) in `boundary_midpoints`.
#include <Eigen/Core>
#include <map>
#include <string>
#include <vector>

#include "fsi/common/gmsh_reader.hpp"

namespace fsi::fluid {

using IndexMatrix4 = Eigen::Matrix<int, Eigen::Dynamic, 4, Eigen::RowMajor>;
using IndexMatrix6 = Eigen::Matrix<int, Eigen::Dynamic, 6, Eigen::RowMajor>;
using IndexMatrixT3 = Eigen::Matrix<int, Eigen::Dynamic, 3, Eigen::RowMajor>;

// The vertices of edge k of a tetrahedron (gmsh's 10-node order: node 4 + k is its midpoint).
constexpr int kTetEdges[6][2] = {{0, 1}, {1, 2}, {2, 0}, {3, 0}, {3, 2}, {3, 1}};

struct TetMesh {
  Eigen::MatrixX3d nodes;                           // reference positions
  IndexMatrix4 tets;                                // positive volume
  std::map<std::string, IndexMatrixT3> boundaries;  // named face groups (vertex triples)
  // Quadratic meshes only (empty otherwise):
  int vertex_count = -1;                                    // -1: every node is a vertex (linear mesh)
  IndexMatrix6 edge_nodes;                                  // midpoint of edge k of each tetrahedron
  std::map<std::string, IndexMatrixT3> boundary_midpoints;  // midpoints of (ab, bc, ca) of each face

  bool quadratic() const { return edge_nodes.rows() > 0; }
  int vertices() const { return vertex_count < 0 ? node_count() : vertex_count; }
  int node_count() const { return static_cast<int>(nodes.rows()); }
  int cell_count() const { return static_cast<int>(tets.rows()); }
  const IndexMatrixT3& boundary(const std::string& name) const;  // throws listing known names
  bool has_boundary(const std::string& name) const { return boundaries.count(name) > 0; }
  // Sorted unique node indices of the named groups (quadratic meshes: with the midpoints).
  std::vector<int> boundary_nodes(const std::vector<std::string>& names) const;
  // The 10 nodes of tetrahedron e (vertices 0-3, then the midpoints of kTetEdges).
  Eigen::Matrix<int, 10, 1> element_nodes10(int e) const;
  // Quadratic meshes: every edge midpoint's row of `values` becomes the mean of its vertices'.
  template <class Values>
  void interpolate_midpoints(Values& values) const {
    if (!quadratic()) return;
    for (int e = 0; e < cell_count(); ++e)
      for (int k = 0; k < 6; ++k)
        values.row(edge_nodes(e, k)) =
            0.5 * (values.row(tets(e, kTetEdges[k][0])) + values.row(tets(e, kTetEdges[k][1])));
  }

  // A quadratic mesh with straight edges from a linear one.
  TetMesh quadratic_from_linear() const;
  // Every 3D group of 4-node (or 10-node) tetrahedra is fluid (or only `domain_groups`); the
  // 2D groups of 3-node (6-node) triangles are the boundaries. Unused nodes are dropped and the
  // rest renumbered (vertices first). std::runtime_error naming the file: no tetrahedra (a 2D
  // mesh), mixed orders, a degenerate tetrahedron.
  static TetMesh from_gmsh(const GmshMesh& mesh, const std::vector<std::string>& domain_groups = {});
  // Structured nx x ny x nz box cut into 6 tetrahedra per cell (Kuhn), boundaries "left" (x0),
  // "right" (x1), "bottom" (y0), "top" (y1), "back" (z0), "front" (z1).
  static TetMesh box(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, int nx, int ny, int nz);
};

}  // namespace fsi::fluid
