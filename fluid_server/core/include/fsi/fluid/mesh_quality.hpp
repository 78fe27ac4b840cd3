#pragma once
// The quality of a moving fluid mesh, for monitoring the mesh motion (and deciding when to
// remesh): per triangle in its current position,
//  - the scaled Jacobian (Verdict's definition): min over the corners of 2 A / (|a| |b|), the
//    two edges at the corner, times 2 / sqrt(3); 1 for the equilateral triangle, 0 for a
//    degenerate one, negative when the triangle is inverted;
//  - the largest interior angle (degrees; 180 for a degenerate triangle);
//  - for 6-node triangles, the curved-element Jacobian: min det J(xi) at the points the solver
//    checks (its quadrature points and the corners) divided by the straight triangle's det J
//    (1 for straight edges; <= 0: the element folds).
// Pure geometry: no solver, no I/O.
#include <Eigen/Core>
#include <string>

#include "fsi/fluid/mesh.hpp"
#include "fsi/fluid/tet_mesh.hpp"

namespace fsi::fluid {

struct MeshQuality {
  double min_scaled_jacobian = 1;  // over all triangles
  double max_angle_deg = 60;       // over all triangles
  double min_curved_jacobian = 1;  // 6-node triangles only (1 for linear meshes)
  int worst_element = -1;          // the triangle of min_scaled_jacobian
  int worst_curved_element = -1;   // the triangle of min_curved_jacobian
  int inverted = 0;                // triangles with a negative area or det J <= 0 somewhere
};

// The quality of `mesh` with its nodes at `positions` (node_count x 2; the reference
// positions plus the mesh displacement).
MeshQuality mesh_quality(const FluidMesh& mesh, const Eigen::MatrixX2d& positions);

// The 3D analogue, per tetrahedron in its current position (its four vertices):
//  - the scaled Jacobian (Verdict's): 6 V over the largest product of the three edge lengths
//    at a corner, times sqrt(2); 1 for the regular tetrahedron, 0 degenerate, < 0 inverted;
//  - the shape quality (mean ratio): 12 (3 |V|)^(2/3) / (sum of the squared edge lengths),
//    signed like V; 1 for the regular tetrahedron, -> 0 for slivers, needles and caps;
//  - the volume ratio: current over reference volume (1 for a rigid motion);
//  - for 10-node tetrahedra, the curved-element Jacobian: min det J at the points the solver
//    checks (p2_tet_min_jacobian: its quadrature points and the vertices) over the straight
//    tetrahedron's det J (1 for straight edges; <= 0: the element folds).
struct TetMeshQuality {
  double min_scaled_jacobian = 1;                          // over all tetrahedra
  double min_shape = 1;                                    // over all tetrahedra
  double min_volume_ratio = 1;                             // over all tetrahedra
  double min_curved_jacobian = 1;                          // 10-node tetrahedra only (1 for linear meshes)
  int worst_element = -1;                                  // the tetrahedron of min_scaled_jacobian
  Eigen::Vector3d worst_centre = Eigen::Vector3d::Zero();  // its centroid (current position)
  int worst_curved_element = -1;                           // the tetrahedron of min_curved_jacobian
  Eigen::Vector3d worst_curved_centre = Eigen::Vector3d::Zero();
  int inverted = 0;  // tetrahedra with a negative volume or det J <= 0 somewhere
  // One line for logs and errors: the minima, where the worst element is, how many are inverted.
  std::string describe() const;
};

// The quality of `mesh` with its nodes at `positions` (node_count x 3).
TetMeshQuality mesh_quality(const TetMesh& mesh, const Eigen::MatrixX3d& positions);

}  // namespace fsi::fluid
