#include "fsi/fluid/mesh_quality.hpp"

#include <algorithm>
#include <cmath>

#include "fsi/fluid/p2p1_element.hpp"

namespace fsi::fluid {

namespace {

double cross(const Eigen::RowVector2d& a, const Eigen::RowVector2d& b) { return a(0) * b(1) - a(1) * b(0); }

// Scaled Jacobian and largest angle (degrees) of the straight triangle p0 p1 p2.
std::pair<double, double> triangle_shape(const Eigen::RowVector2d& p0, const Eigen::RowVector2d& p1,
                                         const Eigen::RowVector2d& p2) {
  const Eigen::RowVector2d e[3] = {p1 - p0, p2 - p1, p0 - p2};  // edge k from corner k to corner k + 1
  const double twice_area = cross(e[0], -e[2]);
  const double len[3] = {e[0].norm(), e[1].norm(), e[2].norm()};
  double scaled = 1e300, max_angle = 0;
  for (int k = 0; k < 3; ++k) {
    const double la = len[k], lb = len[(k + 2) % 3];  // the two edges meeting at corner k
    if (la == 0 || lb == 0) return {0.0, 180.0};
    scaled = std::min(scaled, twice_area / (la * lb));
    const double c = std::clamp(e[k].dot(-e[(k + 2) % 3]) / (la * lb), -1.0, 1.0);
    max_angle = std::max(max_angle, std::acos(c) * 180.0 / M_PI);
  }
  if (twice_area <= 0) max_angle = 180.0;
  return {scaled * 2.0 / std::sqrt(3.0), max_angle};
}

// min det J of the 6-node map over the straight triangle's det J, at the points where the
// solver checks it (p2_min_jacobian: its quadrature points and the corners), so the monitor
// and the solver's "the mesh motion tangled the mesh" agree on when an element folds.
double curved_jacobian(const Eigen::Matrix<double, 6, 2>& x) {
  const double straight = cross(x.row(1) - x.row(0), x.row(2) - x.row(0));
  if (straight <= 0) return straight == 0 ? 0.0 : -1.0;
  return p2_min_jacobian(x) / straight;
}

}  // namespace

MeshQuality mesh_quality(const FluidMesh& mesh, const Eigen::MatrixX2d& positions) {
  MeshQuality q;
  q.min_scaled_jacobian = 1e300;
  q.max_angle_deg = 0;
  for (int e = 0; e < mesh.triangle_count(); ++e) {
    const auto [scaled, angle] = triangle_shape(
        positions.row(mesh.triangles(e, 0)), positions.row(mesh.triangles(e, 1)), positions.row(mesh.triangles(e, 2)));
    bool bad = scaled <= 0;
    if (scaled < q.min_scaled_jacobian) q.min_scaled_jacobian = scaled, q.worst_element = e;
    q.max_angle_deg = std::max(q.max_angle_deg, angle);
    if (mesh.quadratic()) {
      const auto nodes = mesh.element_nodes6(e);
      Eigen::Matrix<double, 6, 2> x;
      for (int k = 0; k < 6; ++k) x.row(k) = positions.row(nodes(k));
      const double curved = curved_jacobian(x);
      if (curved < q.min_curved_jacobian) q.min_curved_jacobian = curved, q.worst_curved_element = e;
      bad = bad || curved <= 0;
    }
    q.inverted += bad;
  }
  if (mesh.triangle_count() == 0) q.min_scaled_jacobian = 1, q.max_angle_deg = 60;
  return q;
}

}  // namespace fsi::fluid
