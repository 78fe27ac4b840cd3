#pragma once
// The fluid's triangle mesh: linear (3-node) triangles, counter-clockwise, and named
// boundary groups of 2-node segments. Built from a gmsh mesh or (for tests) a structured
// rectangle. No I/O besides what read_gmsh did before.
#include <Eigen/Core>

#include <map>
#include <string>
#include <vector>

#include "fsi/common/gmsh_reader.hpp"

namespace fsi::fluid {

using IndexMatrix3 = Eigen::Matrix<int, Eigen::Dynamic, 3, Eigen::RowMajor>;
using IndexMatrix2 = Eigen::Matrix<int, Eigen::Dynamic, 2, Eigen::RowMajor>;

struct FluidMesh {
  Eigen::MatrixX2d nodes;                         // reference positions
  IndexMatrix3 triangles;                         // counter-clockwise
  std::map<std::string, IndexMatrix2> boundaries;  // named segment groups

  int node_count() const { return static_cast<int>(nodes.rows()); }
  int triangle_count() const { return static_cast<int>(triangles.rows()); }
  const IndexMatrix2& boundary(const std::string& name) const;  // throws listing known names
  bool has_boundary(const std::string& name) const { return boundaries.count(name) > 0; }
  // Sorted unique node indices of the named groups.
  std::vector<int> boundary_nodes(const std::vector<std::string>& names) const;

  // Every 2D group of 3-node triangles is fluid (or only `domain_groups` if given); nodes
  // not used by any triangle (e.g. circle centres) are dropped and the rest renumbered.
  static FluidMesh from_gmsh(const GmshMesh& mesh, const std::vector<std::string>& domain_groups = {});
  // Structured nx x ny rectangle cut into 2 triangles per cell (alternating diagonals),
  // boundaries "left", "right", "bottom", "top".
  static FluidMesh rectangle(double x0, double x1, double y0, double y1, int nx, int ny);
};

}  // namespace fsi::fluid
