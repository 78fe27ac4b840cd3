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

#include "fsi/fluid/mesh.hpp"

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

}  // namespace fsi::fluid
