#include "fsi/fluid/mesh_quality.hpp"

#include <fmt/format.h>

#include <Eigen/LU>
#include <algorithm>
#include <cmath>

#include "fsi/fluid/p2p1_element.hpp"
#include "fsi/fluid/p2p1_tet_element.hpp"

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

namespace {

struct TetShape {
  double six_volume, scaled_jacobian, shape;
};

// Scaled Jacobian and mean-ratio shape quality of the straight tetrahedron x (rows: vertices).
TetShape tet_shape(const Eigen::Matrix<double, 4, 3>& x) {
  Eigen::Matrix3d J;
  for (int k = 0; k < 3; ++k) J.col(k) = (x.row(k + 1) - x.row(0)).transpose();
  const double det = J.determinant();  // 6 V
  double len2[4][4] = {};
  double sum = 0;
  for (int a = 0; a < 4; ++a)
    for (int b = a + 1; b < 4; ++b) {
      len2[a][b] = len2[b][a] = (x.row(a) - x.row(b)).squaredNorm();
      sum += len2[a][b];
    }
  double corner = 0;  // largest product of the three edge lengths at a corner
  for (int a = 0; a < 4; ++a) {
    double p = 1;
    for (int b = 0; b < 4; ++b)
      if (b != a) p *= len2[a][b];
    corner = std::max(corner, std::sqrt(p));
  }
  TetShape s{det, 0.0, 0.0};
  if (corner == 0 || sum == 0) return s;
  s.scaled_jacobian = std::sqrt(2.0) * det / corner;
  s.shape = std::copysign(12.0 * std::cbrt(0.25 * det * det) / sum, det);  // (3 |V|)^(2/3) = (|det| / 2)^(2/3)
  return s;
}

}  // namespace

TetMeshQuality mesh_quality(const TetMesh& mesh, const Eigen::MatrixX3d& positions) {
  TetMeshQuality q;
  if (mesh.cell_count() == 0) return q;
  q.min_scaled_jacobian = q.min_shape = q.min_volume_ratio = 1e300;
  for (int e = 0; e < mesh.cell_count(); ++e) {
    Eigen::Matrix<double, 4, 3> x, x0;
    for (int k = 0; k < 4; ++k) {
      x.row(k) = positions.row(mesh.tets(e, k));
      x0.row(k) = mesh.nodes.row(mesh.tets(e, k));
    }
    const TetShape s = tet_shape(x), s0 = tet_shape(x0);
    bool bad = s.six_volume <= 0;
    if (s.scaled_jacobian < q.min_scaled_jacobian) {
      q.min_scaled_jacobian = s.scaled_jacobian;
      q.worst_element = e;
      q.worst_centre = x.colwise().mean().transpose();
    }
    q.min_shape = std::min(q.min_shape, s.shape);
    if (s0.six_volume > 0) q.min_volume_ratio = std::min(q.min_volume_ratio, s.six_volume / s0.six_volume);
    if (mesh.quadratic()) {
      const auto nodes = mesh.element_nodes10(e);
      Eigen::Matrix<double, 10, 3> xc;
      for (int k = 0; k < 10; ++k) xc.row(k) = positions.row(nodes(k));
      const double curved =
          s.six_volume <= 0 ? (s.six_volume == 0 ? 0.0 : -1.0) : p2_tet_min_jacobian(xc) / s.six_volume;
      if (curved < q.min_curved_jacobian) {
        q.min_curved_jacobian = curved;
        q.worst_curved_element = e;
        q.worst_curved_centre = x.colwise().mean().transpose();
      }
      bad = bad || curved <= 0;
    }
    q.inverted += bad;
  }
  return q;
}

std::string TetMeshQuality::describe() const {
  std::string s = fmt::format(
      "min scaled Jacobian {:.3g} (tetrahedron {} near ({:.5g}, {:.5g}, {:.5g})), min shape {:.3g}, "
      "min volume ratio {:.3g}",
      min_scaled_jacobian, worst_element, worst_centre.x(), worst_centre.y(), worst_centre.z(), min_shape,
      min_volume_ratio);
  if (worst_curved_element >= 0)
    s += fmt::format(", min curved Jacobian {:.3g} (tetrahedron {} near ({:.5g}, {:.5g}, {:.5g}))", min_curved_jacobian,
                     worst_curved_element, worst_curved_centre.x(), worst_curved_centre.y(), worst_curved_centre.z());
  if (inverted > 0) s += fmt::format(", {} inverted", inverted);
  return s;
}

}  // namespace fsi::fluid
