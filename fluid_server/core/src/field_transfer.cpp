#include "fsi/fluid/field_transfer.hpp"

#include <fmt/format.h>

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "fsi/fluid/p2p1_element.hpp"

namespace fsi::fluid {

namespace {

// The quadratic shape functions (p2p1_element.hpp) as plain arrays.
void p2(double xi, double eta, double N[6], double dxi[6], double deta[6]) {
  Eigen::Matrix<double, 6, 1> n;
  Eigen::Matrix<double, 6, 2> d;
  p2_shape(xi, eta, n, d);
  for (int k = 0; k < 6; ++k) N[k] = n(k), dxi[k] = d(k, 0), deta[k] = d(k, 1);
}

}  // namespace

MeshLocator::MeshLocator(const FluidMesh& mesh, const Eigen::MatrixX2d& positions) : mesh_(mesh), x_(positions) {
  if (positions.rows() != mesh.node_count())
    throw std::invalid_argument(
        fmt::format("field transfer: {} positions for a mesh of {} nodes", positions.rows(), mesh.node_count()));
  const int nt = std::max(mesh.triangle_count(), 1);
  lo_ = x_.colwise().minCoeff().transpose();
  const Eigen::Vector2d hi = x_.colwise().maxCoeff().transpose();
  const Eigen::Vector2d size = (hi - lo_).cwiseMax(1e-300);
  const double per_cell = std::sqrt(size(0) * size(1) / nt);  // about one triangle per cell
  nx_ = std::clamp(static_cast<int>(size(0) / per_cell), 1, 4096);
  ny_ = std::clamp(static_cast<int>(size(1) / per_cell), 1, 4096);
  cell_ = Eigen::Vector2d(size(0) / nx_, size(1) / ny_);
  buckets_.assign(static_cast<std::size_t>(nx_) * ny_, {});
  for (int e = 0; e < mesh.triangle_count(); ++e) {
    Eigen::Vector2d a = x_.row(mesh.triangles(e, 0)).transpose(), b = a;
    const int corners = mesh.quadratic() ? 6 : 3;
    const auto nodes = mesh.quadratic() ? mesh.element_nodes6(e) : Eigen::Matrix<int, 6, 1>();
    for (int k = 0; k < corners; ++k) {
      const Eigen::Vector2d p = x_.row(mesh.quadratic() ? nodes(k) : mesh.triangles(e, k)).transpose();
      a = a.cwiseMin(p), b = b.cwiseMax(p);
    }
    const int i0 = std::clamp(static_cast<int>((a(0) - lo_(0)) / cell_(0)), 0, nx_ - 1);
    const int i1 = std::clamp(static_cast<int>((b(0) - lo_(0)) / cell_(0)), 0, nx_ - 1);
    const int j0 = std::clamp(static_cast<int>((a(1) - lo_(1)) / cell_(1)), 0, ny_ - 1);
    const int j1 = std::clamp(static_cast<int>((b(1) - lo_(1)) / cell_(1)), 0, ny_ - 1);
    for (int j = j0; j <= j1; ++j)
      for (int i = i0; i <= i1; ++i) buckets_[static_cast<std::size_t>(j) * nx_ + i].push_back(e);
  }
}

// The reference coordinates of p in triangle e (Newton on the curved map for 6-node
// triangles), clamped into the triangle, and the distance of p from the clamped point.
PointLocation MeshLocator::in_triangle(int e, const Eigen::Vector2d& p) const {
  const Eigen::Vector2d p0 = x_.row(mesh_.triangles(e, 0)).transpose(), p1 = x_.row(mesh_.triangles(e, 1)).transpose(),
                        p2v = x_.row(mesh_.triangles(e, 2)).transpose();
  Eigen::Matrix2d J;
  J << p1 - p0, p2v - p0;
  Eigen::Vector2d r = J.inverse() * (p - p0);
  Eigen::Matrix<double, 6, 2> xe;
  if (mesh_.quadratic()) {
    const auto nodes = mesh_.element_nodes6(e);
    for (int k = 0; k < 6; ++k) xe.row(k) = x_.row(nodes(k));
  }
  const auto map = [&](const Eigen::Vector2d& s, Eigen::Matrix2d* jac) {
    if (!mesh_.quadratic()) {
      if (jac) *jac = J;
      return Eigen::Vector2d(p0 + J * s);
    }
    double N[6], a[6], b[6];
    p2(s(0), s(1), N, a, b);
    Eigen::Vector2d x = Eigen::Vector2d::Zero(), dx = x, dy = x;
    for (int k = 0; k < 6; ++k)
      x += N[k] * xe.row(k).transpose(), dx += a[k] * xe.row(k).transpose(), dy += b[k] * xe.row(k).transpose();
    if (jac) *jac << dx, dy;
    return x;
  };
  if (mesh_.quadratic())
    for (int it = 0; it < 20; ++it) {
      Eigen::Matrix2d jac;
      const Eigen::Vector2d f = map(r, &jac) - p;
      const Eigen::Vector2d step = jac.inverse() * f;
      r -= step;
      if (!r.allFinite()) {
        r = J.inverse() * (p - p0);
        break;
      }
      if (step.norm() < 1e-14) break;
    }
  const double tol = 1e-12;
  PointLocation loc{e, r(0), r(1), 0.0};
  if (r(0) >= -tol && r(1) >= -tol && r(0) + r(1) <= 1 + tol) return loc;
  // Outside: the closest point of the (straight) triangle, then its reference coordinates.
  double best = 1e300;
  Eigen::Vector2d closest = p0;
  const Eigen::Vector2d v[3] = {p0, p1, p2v};
  for (int k = 0; k < 3; ++k) {
    const Eigen::Vector2d a = v[k], d = v[(k + 1) % 3] - a;
    const double t = std::clamp((p - a).dot(d) / d.squaredNorm(), 0.0, 1.0);
    const Eigen::Vector2d q = a + t * d;
    if ((q - p).norm() < best) best = (q - p).norm(), closest = q;
  }
  Eigen::Vector2d s = J.inverse() * (closest - p0);
  s = s.cwiseMax(0.0);
  if (s.sum() > 1) s /= s.sum();
  loc.xi = s(0), loc.eta = s(1);
  loc.distance = (map(s, nullptr) - p).norm();
  return loc;
}

PointLocation MeshLocator::locate(const Eigen::Vector2d& p) const {
  const int ci = std::clamp(static_cast<int>(std::floor((p(0) - lo_(0)) / cell_(0))), 0, nx_ - 1);
  const int cj = std::clamp(static_cast<int>(std::floor((p(1) - lo_(1)) / cell_(1))), 0, ny_ - 1);
  PointLocation best;
  best.distance = 1e300;
  // Rings of buckets around p's: inside a triangle ends the search; otherwise keep the
  // nearest triangle and stop one ring after the first candidate.
  int found_ring = -1;
  for (int ring = 0; ring < std::max(nx_, ny_); ++ring) {
    for (int j = cj - ring; j <= cj + ring; ++j)
      for (int i = ci - ring; i <= ci + ring; ++i) {
        if (i < 0 || j < 0 || i >= nx_ || j >= ny_) continue;
        if (std::max(std::abs(i - ci), std::abs(j - cj)) != ring) continue;
        for (int e : buckets_[static_cast<std::size_t>(j) * nx_ + i]) {
          const PointLocation loc = in_triangle(e, p);
          if (loc.distance == 0) return loc;
          if (loc.distance < best.distance) best = loc;
        }
      }
    if (best.element >= 0 && found_ring < 0) found_ring = ring;
    if (found_ring >= 0 && ring >= found_ring + 1) break;
  }
  return best;
}

Eigen::MatrixXd interpolate_field(const MeshLocator& locator, const FluidMesh& mesh, const Eigen::MatrixXd& field,
                                  const Eigen::MatrixX2d& points, TransferReport* report) {
  const bool p2_field = mesh.quadratic() && field.rows() == mesh.node_count();
  if (!p2_field && field.rows() != mesh.vertices())
    throw std::invalid_argument(fmt::format("field transfer: a field of {} rows on a mesh of {} nodes ({} vertices)",
                                            field.rows(), mesh.node_count(), mesh.vertices()));
  Eigen::MatrixXd out(points.rows(), field.cols());
  TransferReport rep;
  rep.points = static_cast<int>(points.rows());
  for (Eigen::Index q = 0; q < points.rows(); ++q) {
    const PointLocation loc = locator.locate(points.row(q).transpose());
    if (loc.element < 0) throw std::runtime_error("field transfer: the source mesh has no triangles");
    if (loc.distance > 0) ++rep.outside, rep.max_distance = std::max(rep.max_distance, loc.distance);
    if (p2_field) {
      double N[6], a[6], b[6];
      p2(loc.xi, loc.eta, N, a, b);
      const auto nodes = mesh.element_nodes6(loc.element);
      out.row(q).setZero();
      for (int k = 0; k < 6; ++k) out.row(q) += N[k] * field.row(nodes(k));
    } else {
      const double N[3] = {1 - loc.xi - loc.eta, loc.xi, loc.eta};
      out.row(q).setZero();
      for (int k = 0; k < 3; ++k) out.row(q) += N[k] * field.row(mesh.triangles(loc.element, k));
    }
  }
  if (report) *report = rep;
  return out;
}

}  // namespace fsi::fluid
