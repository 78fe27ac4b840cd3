#pragma once
// Reads gmsh ASCII meshes (MSH 2.2 and 4.1) with named physical groups.
//   auto mesh = fsi::read_gmsh("configs/meshes/dfg.msh");
//   const auto& fluid = mesh.group("fluid");        // 2D cells
//   const auto& wall  = mesh.group("cylinder");     // boundary lines
// A file that is not a mesh, or a missing group, is a std::runtime_error naming the file,
// the line and (for groups) the names that exist.
#include <Eigen/Core>
#include <filesystem>
#include <istream>
#include <string>
#include <vector>

namespace fsi {

struct GmshGroup {
  std::string name;   // physical name ("" if unnamed; then "tag<N>")
  int dimension = 0;  // 1 = lines, 2 = surface cells, 3 = tetrahedra or hexahedra
  int physical_tag = 0;
  int element_type = 0;  // gmsh type: 1 line2, 2 tri3, 3 quad4, 4 tet4, 5 hex8, 8 line3, 9 tri6, 10 quad9, 11 tet10
  Eigen::Matrix<int, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> elements;  // 0-based node indices
};

struct GmshMesh {
  Eigen::MatrixX2d nodes;   // x, y of every node (0-based index)
  Eigen::VectorXd z;        // z of every node (0 in a planar mesh)
  bool has_volume() const;  // a group of tetrahedra or hexahedra (a 3D mesh)
  std::vector<GmshGroup> groups;
  const GmshGroup& group(const std::string& name) const;  // throws listing known names
  bool has_group(const std::string& name) const;
  std::filesystem::path source;
};

GmshMesh read_gmsh(const std::filesystem::path& path);
// The same from a stream (e.g. an in-memory mesh); `name` stands for the file in messages.
GmshMesh read_gmsh(std::istream& in, const std::filesystem::path& name);

}  // namespace fsi
