#pragma once
// The fluid's triangle mesh: linear (3-node) or quadratic (6-node) triangles,
// counter-clockwise, and named boundary groups of segments. Built from a gmsh mesh or (for
// tests) a structured rectangle. No I/O besides what read_gmsh did before.
//
// Quadratic meshes (Taylor-Hood P2/P1): the vertices are nodes 0 .. vertex_count - 1, the
// edge midpoints (possibly curved: gmsh -order 2 puts them on the geometry) follow;
// `triangles` holds the three vertices, `edge_nodes(e, k)` the node of edge (k, k+1 mod 3),
// and every boundary segment (a, b) has its midpoint in `boundary_midpoints`.
#include <Eigen/Core>
#include <map>
#include <string>
#include <vector>

#include "fsi/common/gmsh_reader.hpp"

namespace fsi::fluid {

using IndexMatrix3 = Eigen::Matrix<int, Eigen::Dynamic, 3, Eigen::RowMajor>;
using IndexMatrix2 = Eigen::Matrix<int, Eigen::Dynamic, 2, Eigen::RowMajor>;

struct FluidMesh {
  Eigen::MatrixX2d nodes;                          // reference positions
  IndexMatrix3 triangles;                          // counter-clockwise
  std::map<std::string, IndexMatrix2> boundaries;  // named segment groups (vertex pairs)
  // Quadratic meshes only (empty otherwise):
  int vertex_count = -1;                                      // -1: every node is a vertex (linear mesh)
  IndexMatrix3 edge_nodes;                                    // midpoint of edge (k, k+1) of each triangle
  std::map<std::string, Eigen::VectorXi> boundary_midpoints;  // midpoint of each segment of a group

  bool quadratic() const { return edge_nodes.rows() > 0; }
  int vertices() const { return vertex_count < 0 ? node_count() : vertex_count; }

  int node_count() const { return static_cast<int>(nodes.rows()); }
  int triangle_count() const { return static_cast<int>(triangles.rows()); }
  int cell_count() const { return triangle_count(); }
  const IndexMatrix2& boundary(const std::string& name) const;  // throws listing known names
  bool has_boundary(const std::string& name) const { return boundaries.count(name) > 0; }
  // Sorted unique node indices of the named groups (quadratic meshes: with the midpoints).
  std::vector<int> boundary_nodes(const std::vector<std::string>& names) const;
  // The 6 nodes of triangle e (vertices 0-2, then the midpoints of edges 01, 12, 20).
  Eigen::Matrix<int, 6, 1> element_nodes6(int e) const;

  // Quadratic meshes: the row of every edge midpoint in `values` (one row per node) becomes the
  // mean of its two vertices' rows (straight edges). Linear meshes: nothing to do.
  template <class Values>
  void interpolate_midpoints(Values& values) const {
    if (!quadratic()) return;
    for (int e = 0; e < triangle_count(); ++e)
      for (int k = 0; k < 3; ++k)
        values.row(edge_nodes(e, k)) = 0.5 * (values.row(triangles(e, k)) + values.row(triangles(e, (k + 1) % 3)));
  }

  // A quadratic mesh with straight edges (midpoints at the edge centres) from a linear one.
  FluidMesh quadratic_from_linear() const;
  // A quadratic mesh cut into 4 linear triangles per element on the same nodes (mesh motion,
  // output); boundary segments are split at their midpoints. A linear mesh is returned as is.
  FluidMesh linear_refinement() const;

  // Every 2D group of 3-node (or 6-node) triangles is fluid (or only `domain_groups` if
  // given); nodes not used by any triangle (e.g. circle centres) are dropped and the rest
  // renumbered (vertices first). Mixed 3-/6-node groups are an error.
  static FluidMesh from_gmsh(const GmshMesh& mesh, const std::vector<std::string>& domain_groups = {});
  // Structured nx x ny rectangle cut into 2 triangles per cell (alternating diagonals),
  // boundaries "left", "right", "bottom", "top".
  static FluidMesh rectangle(double x0, double x1, double y0, double y1, int nx, int ny);
};

}  // namespace fsi::fluid
