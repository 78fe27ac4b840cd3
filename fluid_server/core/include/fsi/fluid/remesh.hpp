#pragma once
// Remeshing a (deformed) fluid mesh with the gmsh library in-process: every boundary vertex
// and boundary edge of the current mesh is kept (positions, and for 6-node meshes the edge
// midpoints, possibly curved), only the interior is regenerated. The local element size
// follows the mesh being replaced: a background field (a gmsh list-based view "ST") with, at
// every vertex, the mean size sqrt(4 A / sqrt(3)) of its triangles in their *reference*
// configuration, placed at their current positions; so the scene's sizes (fine at a leaflet,
// coarse far away) are kept and travel with the body.
//
// Numbering: the kept boundary vertices first, in their old order, then the new interior
// vertices; for 6-node meshes the kept boundary midpoints (old order), then the interior
// midpoints (straight, at the edge centres). So the nodes of every boundary group (the
// interface) keep their order and their segments: an interface mapping built on the old mesh
// stays valid. Boundary groups are carried over.
#include <Eigen/Core>
#include <vector>

#include "fsi/fluid/mesh.hpp"

namespace fsi::fluid {

struct RemeshResult {
  FluidMesh mesh;               // its reference positions are the old mesh's current ones
  std::vector<int> old_node;    // per new node: the old node it is (kept boundary nodes), or -1
  Eigen::VectorXd vertex_size;  // the target size at every new vertex (interpolated from the old one)
  double seconds = 0;           // wall time in gmsh and the renumbering
};

// `positions`: the old mesh's nodes where they are now (node_count x 2). Throws
// std::runtime_error when gmsh fails or the new mesh has an inverted triangle.
// `vertex_size`: the target size at every old vertex (empty: reference_sizes(mesh)); carried
// from remesh to remesh (interpolated at the new vertices), so repeated remeshes keep the
// scene's sizes instead of drifting with each mesh's own.
RemeshResult remesh(const FluidMesh& mesh, const Eigen::MatrixX2d& positions,
                    const Eigen::VectorXd& vertex_size = Eigen::VectorXd());
// Per vertex the mean size sqrt(4 A / sqrt(3)) of its triangles (reference positions).
Eigen::VectorXd reference_sizes(const FluidMesh& mesh);

}  // namespace fsi::fluid
