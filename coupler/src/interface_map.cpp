#include "fsi/coupling/interface_map.hpp"

#include <fmt/format.h>

#include <Eigen/LU>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <stdexcept>
#include <vector>

#include "fsi/common/interface_geometry.hpp"

namespace fsi::coupling {

std::string to_string(MappingKind k) {
  return k == MappingKind::NearestSegment       ? "nearest-segment"
         : k == MappingKind::RbfThinPlateSpline ? "rbf-tps"
                                                : "rbf-wendland-c2";
}

InterfaceMap::InterfaceMap(const InterfaceMeshData& solid, const InterfaceMeshData& fluid,
                           const MappingSettings& mapping)
    : kind_(mapping.kind) {
  const Eigen::Index ns = solid.coordinates.rows(), nf = fluid.coordinates.rows();
  if (ns == 0 && nf == 0) {
    h_.resize(0, 0);
    ht_.resize(0, 0);
    hs_.resize(0, 0);
    hst_.resize(0, 0);
    return;
  }
  if (ns == 0 || nf == 0)
    throw std::invalid_argument(
        fmt::format("interface mismatch: the solid has {} interface nodes, the fluid {}", ns, nf));
  if (solid.dimension != fluid.dimension)
    throw std::invalid_argument(fmt::format(
        "interface mismatch: the solid's interface is {}D ({} values per node), the fluid's {}D: both servers must "
        "describe the same space",
        solid.dimension, solid.dimension, fluid.dimension, fluid.dimension));
  dim_ = solid.dimension;
  if (dim_ == 3) {
    build_nearest_3d(solid, fluid);
    if (kind_ != MappingKind::NearestSegment) build_rbf<3>(solid, fluid, mapping);
    detect_conforming<3>(solid, fluid);
    return;
  }
  std::vector<Eigen::Triplet<double>> t, ts;
  for (Eigen::Index i = 0; i < nf; ++i) {
    const Eigen::Vector2d p = fluid.coordinates.row(i).transpose();
    double best = std::numeric_limits<double>::infinity();
    int a = 0, b = 0;
    double xi = 0;
    if (solid.segments.empty()) {
      for (Eigen::Index j = 0; j < ns; ++j) {
        const double dist = (solid.coordinates.row(j).transpose() - p).norm();
        if (dist < best) best = dist, a = b = static_cast<int>(j), xi = 0;
      }
    } else {
      for (const auto& seg : solid.segments) {
        const Eigen::Vector2d x0 = solid.coordinates.row(seg[0]).transpose();
        const Eigen::Vector2d x1 = solid.coordinates.row(seg[1]).transpose();
        const Eigen::Vector2d e = x1 - x0;
        const double len2 = e.squaredNorm();
        double s = len2 > 0 ? (p - x0).dot(e) / len2 : 0.0;
        s = std::clamp(s, 0.0, 1.0);
        const double dist = (x0 + s * e - p).norm();
        if (dist < best) best = dist, a = seg[0], b = seg[1], xi = s;
      }
    }
    max_gap_ = std::max(max_gap_, best);
    for (int c = 0; c < 2; ++c) {
      t.emplace_back(2 * i + c, 2 * a + c, 1.0 - xi);
      if (xi > 0) t.emplace_back(2 * i + c, 2 * b + c, xi);
    }
    ts.emplace_back(i, a, 1.0 - xi);
    if (xi > 0) ts.emplace_back(i, b, xi);
  }
  h_.resize(2 * nf, 2 * ns);
  h_.setFromTriplets(t.begin(), t.end());
  ht_ = h_.transpose();
  hs_.resize(nf, ns);
  hs_.setFromTriplets(ts.begin(), ts.end());
  hst_ = hs_.transpose();

  if (kind_ != MappingKind::NearestSegment) build_rbf<2>(solid, fluid, mapping);
  detect_conforming<2>(solid, fluid);
}

// 3D: each fluid node takes the solid's interpolant at its closest point on the solid's
// faces (nearest node for a point interface). Faces are visited in the order of the distance
// to their bounding boxes, and the search stops when that bound exceeds the best distance.
void InterfaceMap::build_nearest_3d(const InterfaceMeshData& solid, const InterfaceMeshData& fluid) {
  const Eigen::Index ns = solid.coordinates.rows(), nf = fluid.coordinates.rows();
  std::vector<Eigen::Triplet<double>> ts;
  if (solid.faces.empty()) {
    for (Eigen::Index i = 0; i < nf; ++i) {
      double best = std::numeric_limits<double>::infinity();
      Eigen::Index k = 0;
      for (Eigen::Index j = 0; j < ns; ++j) {
        const double dist = (solid.coordinates.row(j) - fluid.coordinates.row(i)).norm();
        if (dist < best) best = dist, k = j;
      }
      max_gap_ = std::max(max_gap_, best);
      ts.emplace_back(i, k, 1.0);
    }
  } else {
    const std::size_t nfaces = solid.faces.size();
    std::vector<Eigen::Vector3d> lo(nfaces), hi(nfaces);
    for (std::size_t f = 0; f < nfaces; ++f) {
      lo[f] = hi[f] = solid.coordinates.row(solid.faces[f].nodes[0]).transpose();
      for (int v : solid.faces[f].nodes) {
        lo[f] = lo[f].cwiseMin(solid.coordinates.row(v).transpose());
        hi[f] = hi[f].cwiseMax(solid.coordinates.row(v).transpose());
      }
      // curved quadratic faces bulge beyond their nodes' box by a fraction of its size
      if (solid.faces[f].nodes.size() > 4) {
        const Eigen::Vector3d pad = Eigen::Vector3d::Constant(0.25 * (hi[f] - lo[f]).norm());
        lo[f] -= pad, hi[f] += pad;
      }
    }
    std::vector<std::pair<double, std::size_t>> order(nfaces);
    Eigen::VectorXd N;
    Eigen::MatrixX2d dN;
    for (Eigen::Index i = 0; i < nf; ++i) {
      const Eigen::Vector3d p = fluid.coordinates.row(i).transpose();
      for (std::size_t f = 0; f < nfaces; ++f) order[f] = {(p - p.cwiseMax(lo[f]).cwiseMin(hi[f])).norm(), f};
      std::sort(order.begin(), order.end());
      double best = std::numeric_limits<double>::infinity();
      FaceProjection best_projection;
      std::size_t best_face = 0;
      for (const auto& [bound, f] : order) {
        if (bound > best) break;
        const FaceProjection q = project_on_face(solid.coordinates, solid.faces[f], p);
        if (q.distance < best) best = q.distance, best_projection = q, best_face = f;
      }
      max_gap_ = std::max(max_gap_, best);
      const InterfaceFace& face = solid.faces[best_face];
      face_shape(static_cast<int>(face.nodes.size()), best_projection.xi, best_projection.eta, N, dN);
      for (std::size_t a = 0; a < face.nodes.size(); ++a)
        if (N[static_cast<Eigen::Index>(a)] != 0.0) ts.emplace_back(i, face.nodes[a], N[static_cast<Eigen::Index>(a)]);
    }
  }
  Eigen::SparseMatrix<double> hs(nf, ns);
  hs.setFromTriplets(ts.begin(), ts.end());  // duplicates (none expected) would add up
  set_from_scalar(Eigen::MatrixXd(hs));
  hs_dense_.resize(0, 0);  // the projection is sparse: keep the sparse products
}

void InterfaceMap::set_from_scalar(const Eigen::MatrixXd& hs) {
  std::vector<Eigen::Triplet<double>> t, ts;
  for (Eigen::Index i = 0; i < hs.rows(); ++i)
    for (Eigen::Index j = 0; j < hs.cols(); ++j) {
      const double w = hs(i, j);
      if (w == 0.0) continue;
      ts.emplace_back(i, j, w);
      for (int c = 0; c < dim_; ++c) t.emplace_back(dim_ * i + c, dim_ * j + c, w);
    }
  h_.resize(dim_ * hs.rows(), dim_ * hs.cols());
  h_.setFromTriplets(t.begin(), t.end());
  ht_ = h_.transpose();
  hs_.resize(hs.rows(), hs.cols());
  hs_.setFromTriplets(ts.begin(), ts.end());
  hst_ = hs_.transpose();
  hs_dense_ = hs;
}

// RBF interpolation on the solid's interface nodes x_j (the centres), evaluated at the
// fluid's nodes:  s(x) = sum_j lambda_j phi(|x - x_j|) + p(x),  p linear,
//   [Phi  P] [lambda]   [u]
//   [P^T  0] [  a   ] = [0]   (C, symmetric),   H = [Phi_fs  P_f] C^{-1} [I; 0].
// Coordinates are centred on the solid's nodes and scaled by their bounding-box diagonal L
// (the thin-plate spline's interpolant does not depend on the scale, given the linear term;
// Wendland's radius is scaled with them). The linear terms are taken along the principal
// axes of the solid's nodes, and an axis without extent (nodes on a line) is dropped, as its
// column of P would be zero and C singular.
template <int D>
void InterfaceMap::build_rbf(const InterfaceMeshData& solid, const InterfaceMeshData& fluid,
                             const MappingSettings& mapping) {
  using Points = Eigen::Matrix<double, Eigen::Dynamic, D>;
  using Row = Eigen::Matrix<double, 1, D>;
  const Eigen::Index ns = solid.coordinates.rows(), nf = fluid.coordinates.rows();
  const Points xs = solid.coordinates, xf = fluid.coordinates;
  const Row centre = xs.colwise().mean();
  const double diagonal = (xs.colwise().maxCoeff() - xs.colwise().minCoeff()).norm();
  const double scale = diagonal > 0 ? diagonal : 1.0;
  const Points ys = (xs.rowwise() - centre) / scale;
  const Points yf = (xf.rowwise() - centre) / scale;

  // Principal axes with an RMS extent above 1e-9 L.
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(Eigen::MatrixXd(ys), Eigen::ComputeFullV);
  std::vector<Eigen::Matrix<double, D, 1>> axes;
  for (int k = 0; k < D; ++k)
    if (svd.singularValues()[k] > 1e-9 * std::sqrt(static_cast<double>(ns))) axes.push_back(svd.matrixV().col(k));
  linear_terms_ = static_cast<int>(axes.size());
  const Eigen::Index np = 1 + linear_terms_, n = ns + np;

  // Node spacing: the largest distance from a solid node to its nearest neighbour.
  double spacing = 0;
  for (Eigen::Index i = 0; i < ns; ++i) {
    double nearest = std::numeric_limits<double>::infinity();
    for (Eigen::Index j = 0; j < ns; ++j)
      if (j != i) nearest = std::min(nearest, (ys.row(i) - ys.row(j)).norm());
    if (std::isfinite(nearest)) spacing = std::max(spacing, nearest);
  }
  const bool wendland = kind_ == MappingKind::RbfWendlandC2;
  if (wendland) {
    support_radius_ = mapping.support_radius > 0 ? mapping.support_radius
                      : spacing > 0              ? MappingSettings::support_factor * spacing * scale
                                                 : scale;
  }
  const double radius = support_radius_ / scale;
  auto phi = [&](double r) {
    if (wendland) {
      const double q = r / radius;
      if (q >= 1) return 0.0;
      const double a = 1 - q, a2 = a * a;
      return a2 * a2 * (4 * q + 1);
    }
    return r > 0 ? r * r * std::log(r) : 0.0;
  };
  auto poly = [&](const Row& y, Eigen::Ref<Eigen::RowVectorXd> row) {
    row[0] = 1;
    for (int k = 0; k < linear_terms_; ++k) row[1 + k] = y.dot(axes[static_cast<std::size_t>(k)].transpose());
  };

  Eigen::MatrixXd c = Eigen::MatrixXd::Zero(n, n);
  for (Eigen::Index i = 0; i < ns; ++i) {
    for (Eigen::Index j = 0; j < ns; ++j) c(i, j) = phi((ys.row(i) - ys.row(j)).norm());
    Eigen::RowVectorXd p(np);
    poly(ys.row(i), p);
    c.block(i, ns, 1, np) = p;
    c.block(ns, i, np, 1) = p.transpose();
  }
  Eigen::MatrixXd bt(n, nf);  // B^T, B = [Phi_fs  P_f]
  for (Eigen::Index i = 0; i < nf; ++i) {
    for (Eigen::Index j = 0; j < ns; ++j) bt(j, i) = phi((yf.row(i) - ys.row(j)).norm());
    Eigen::RowVectorXd p(np);
    poly(yf.row(i), p);
    bt.block(ns, i, np, 1) = p.transpose();
  }
  const Eigen::FullPivLU<Eigen::MatrixXd> lu(c);
  if (!lu.isInvertible())
    throw std::invalid_argument(fmt::format(
        "coupling.mapping {}: the interpolation system on the solid's {} interface nodes is singular (rank {} of {}: "
        "coinciding nodes?)",
        to_string(kind_), ns, lu.rank(), n));
  condition_ = 1.0 / lu.rcond();
  // C symmetric: H^T = [I 0] C^{-1} B^T.
  const Eigen::MatrixXd ht = lu.solve(bt).topRows(ns);
  set_from_scalar(ht.transpose());
}

// Conforming? The nearest solid node of every fluid node (detection only: H stays the
// projection above, or the RBF interpolation, either of which is P to round-off for
// coinciding nodes).
template <int D>
void InterfaceMap::detect_conforming(const InterfaceMeshData& solid, const InterfaceMeshData& fluid) {
  const Eigen::Index ns = solid.coordinates.rows(), nf = fluid.coordinates.rows();
  Eigen::Matrix<double, D, 1> lo = solid.coordinates.colwise().minCoeff().transpose();
  Eigen::Matrix<double, D, 1> hi = solid.coordinates.colwise().maxCoeff().transpose();
  lo = lo.cwiseMin(fluid.coordinates.colwise().minCoeff().transpose());
  hi = hi.cwiseMax(fluid.coordinates.colwise().maxCoeff().transpose());
  tolerance_ = 1e-9 * (hi - lo).norm();
  std::vector<Eigen::Index> match(static_cast<std::size_t>(nf), -1);
  std::vector<char> taken(static_cast<std::size_t>(ns), 0);
  bool distinct = true;
  for (Eigen::Index i = 0; i < nf; ++i) {
    double best = std::numeric_limits<double>::infinity();
    Eigen::Index k = -1;
    for (Eigen::Index j = 0; j < ns; ++j) {
      const double dist = (solid.coordinates.row(j) - fluid.coordinates.row(i)).norm();
      if (dist < best) best = dist, k = j;
    }
    if (best > tolerance_) continue;
    ++coincident_nodes_;
    match[static_cast<std::size_t>(i)] = k;
    if (taken[static_cast<std::size_t>(k)]) distinct = false;
    taken[static_cast<std::size_t>(k)] = 1;
  }
  conforming_ = nf == ns && coincident_nodes_ == nf && distinct;
  if (conforming_) {
    for (int col = 0; col < hs_.outerSize(); ++col)
      for (Eigen::SparseMatrix<double>::InnerIterator it(hs_, col); it; ++it) {
        const double p = match[static_cast<std::size_t>(it.row())] == it.col() ? 1.0 : 0.0;
        permutation_error_ = std::max(permutation_error_, std::abs(it.value() - p));
      }
  }
}

NodalMatrix InterfaceMap::mass_to_solid(const NodalMatrix& fluid_mass) const {
  if (fluid_mass.rows() != hs_.rows() || fluid_mass.cols() != hs_.rows())
    throw std::invalid_argument(
        fmt::format("interface mass of the fluid is {} x {}, expected {} x {} (its interface nodes)", fluid_mass.rows(),
                    fluid_mass.cols(), hs_.rows(), hs_.rows()));
  if (hs_dense_.size() > 0) {  // RBF: H is dense, a dense product is much faster than a sparse one
    const Eigen::MatrixXd mh = fluid_mass * hs_dense_;
    const Eigen::MatrixXd dense = hs_dense_.transpose() * mh;
    NodalMatrix m = dense.sparseView(0.0, 0.0);
    m.makeCompressed();
    return m;
  }
  NodalMatrix m = hst_ * fluid_mass * hs_;
  m.makeCompressed();
  return m;
}

Eigen::SparseMatrix<double> interface_mass(const InterfaceMeshData& solid, const Eigen::VectorXd& displacement) {
  // The nodal mass acting on every component: (M (x) I_d).
  const NodalMatrix nodal = nodal_interface_mass(solid, displacement);
  const int d = solid.dimension;
  std::vector<Eigen::Triplet<double>> t;
  t.reserve(static_cast<std::size_t>(d) * static_cast<std::size_t>(nodal.nonZeros()));
  for (int col = 0; col < nodal.outerSize(); ++col)
    for (NodalMatrix::InnerIterator it(nodal, col); it; ++it)
      for (int c = 0; c < d; ++c) t.emplace_back(d * it.row() + c, d * it.col() + c, it.value());
  Eigen::SparseMatrix<double> m(d * nodal.rows(), d * nodal.cols());
  m.setFromTriplets(t.begin(), t.end());
  return m;
}

}  // namespace fsi::coupling
