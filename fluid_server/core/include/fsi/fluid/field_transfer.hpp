#pragma once
// Moving nodal fields from one fluid mesh to another (remeshing, starting a run from another
// run's state on another mesh): locate each target point in the source mesh (a bucket grid
// over the source's current node positions), then interpolate with the source's own shape
// functions: P1 on the vertices, isoparametric P2 on 6-node triangles (the reference point
// found by Newton's method on the curved map). Linear fields are carried exactly by P1, and
// quadratic ones by P2 on straight-sided elements. A point outside the source mesh (a new
// boundary that bulges out by a little) takes the value at the closest point of the nearest
// triangle; how many did, and how far, is reported.
// Pure geometry and interpolation: no solver, no I/O.
#include <Eigen/Core>
#include <vector>

#include "fsi/fluid/mesh.hpp"

namespace fsi::fluid {

struct PointLocation {
  int element = -1;        // the source triangle
  double xi = 0, eta = 0;  // its reference coordinates (clamped into the triangle when outside)
  double distance = 0;     // 0 inside; outside: the distance to the triangle
};

class MeshLocator {
 public:
  // `positions`: the source mesh's nodes where they are now (node_count x 2).
  MeshLocator(const FluidMesh& mesh, const Eigen::MatrixX2d& positions);
  PointLocation locate(const Eigen::Vector2d& p) const;

 private:
  PointLocation in_triangle(int e, const Eigen::Vector2d& p) const;
  const FluidMesh& mesh_;
  Eigen::MatrixX2d x_;
  Eigen::Vector2d lo_, cell_;
  int nx_ = 1, ny_ = 1;
  std::vector<std::vector<int>> buckets_;
};

struct TransferReport {
  int points = 0;
  int outside = 0;          // points not inside any source triangle
  double max_distance = 0;  // the farthest of them from the source mesh
};

// The values at `points` of a nodal field of the source mesh: `field` has one row per source
// node (P2 on a quadratic mesh, P1 on a linear one) or one row per vertex (P1 on either).
Eigen::MatrixXd interpolate_field(const MeshLocator& locator, const FluidMesh& mesh, const Eigen::MatrixXd& field,
                                  const Eigen::MatrixX2d& points, TransferReport* report = nullptr);

}  // namespace fsi::fluid
