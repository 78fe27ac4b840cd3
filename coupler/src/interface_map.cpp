#include "fsi/coupling/interface_map.hpp"

#include <fmt/format.h>

#include <Eigen/Cholesky>
#include <Eigen/QR>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
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

namespace {

Eigen::Vector3d point(const InterfaceMeshData& mesh, int node) { return mesh.coordinates.row(node).transpose(); }

std::string at(const InterfaceMeshData& mesh, int node) {
  const Eigen::Vector3d x = point(mesh, node);
  return fmt::format("({:.6g}, {:.6g}, {:.6g})", x.x(), x.y(), x.z());
}

// The edges between the corner nodes of one side's faces. Refuses an edge with more than two
// faces (non-manifold) and an edge whose two faces run along it in the same direction
// (inconsistent orientation); returns the boundary edges (one face), as node pairs.
std::vector<std::array<int, 2>> boundary_edges(const InterfaceMeshData& mesh, const char* side) {
  struct Uses {
    int count = 0, face = -1;
    bool forward = true;  // the first face's direction: from the lower to the higher node
  };
  std::map<std::pair<int, int>, Uses> edges;
  const int n = static_cast<int>(mesh.coordinates.rows());
  for (std::size_t f = 0; f < mesh.faces.size(); ++f) {
    const auto& nodes = mesh.faces[f].nodes;
    const int corners = face_is_triangle(static_cast<int>(nodes.size())) ? 3 : 4;
    for (int v : nodes)
      if (v < 0 || v >= n)
        throw std::invalid_argument(
            fmt::format("interface mismatch: the {}'s interface face {} names node {} of {}", side, f, v, n));
    for (int k = 0; k < corners; ++k) {
      const int a = nodes[static_cast<std::size_t>(k)], b = nodes[static_cast<std::size_t>((k + 1) % corners)];
      Uses& e = edges[std::minmax(a, b)];
      if (++e.count == 1) {
        e.face = static_cast<int>(f), e.forward = a < b;
        continue;
      }
      if (e.count > 2)
        throw std::invalid_argument(fmt::format(
            "interface mismatch: the {}'s interface is not a surface: its edge from {} to {} belongs to 3 or more "
            "faces (a non-manifold edge: faces {}, {}, ...)",
            side, at(mesh, a), at(mesh, b), e.face, f));
      if (e.forward == (a < b))
        throw std::invalid_argument(fmt::format(
            "interface mismatch: the {}'s interface faces are not consistently oriented: faces {} and {} run along "
            "their common edge from {} to {} in the same direction (one of them is reversed)",
            side, e.face, f, at(mesh, a), at(mesh, b)));
    }
  }
  std::vector<std::array<int, 2>> out;
  for (const auto& [key, e] : edges)
    if (e.count == 1) out.push_back({key.first, key.second});
  return out;
}

double segment_distance(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  const Eigen::Vector3d e = b - a;
  const double len2 = e.squaredNorm();
  const double s = len2 > 0 ? std::clamp((p - a).dot(e) / len2, 0.0, 1.0) : 0.0;
  return (a + s * e - p).norm();
}

// The distance from p to the closest point of a surface's faces.
double surface_distance(const InterfaceMeshData& mesh, const Eigen::Vector3d& p) {
  double best = std::numeric_limits<double>::infinity();
  for (const auto& face : mesh.faces) best = std::min(best, project_on_face(mesh.coordinates, face, p).distance);
  return best;
}

// Every boundary edge of `mine` (its end points and midpoint) within half the element size
// (the larger of the two edges' lengths) of a boundary edge of `other`, beyond the point's
// distance to `other`'s surface.
void expect_boundary_on(const InterfaceMeshData& mine, const std::vector<std::array<int, 2>>& my_edges,
                        const char* my_side, const InterfaceMeshData& other,
                        const std::vector<std::array<int, 2>>& other_edges, const char* other_side) {
  for (const auto& [a, b] : my_edges) {
    const Eigen::Vector3d xa = point(mine, a), xb = point(mine, b);
    const double length = (xb - xa).norm();
    for (const Eigen::Vector3d& p : {xa, xb, Eigen::Vector3d(0.5 * (xa + xb))}) {
      double best = std::numeric_limits<double>::infinity(), tolerance = 0;
      for (const auto& [c, d] : other_edges) {
        const Eigen::Vector3d xc = point(other, c), xd = point(other, d);
        const double dist = segment_distance(p, xc, xd);
        if (dist < best) best = dist, tolerance = 0.5 * std::max(length, (xd - xc).norm());
      }
      if (best <= tolerance) continue;
      // An interface offset from the other (coupling.interface_gap judges the offset) moves its
      // boundary as far: only the distance to the other boundary beyond the offset counts.
      const double offset = surface_distance(other, p);
      if (best <= tolerance + offset) continue;
      throw std::invalid_argument(fmt::format(
          "interface mismatch: the {}'s interface has a boundary edge from {} to {} (an edge of one face only) "
          "{}: the two sides' face sets do not cover the same surface (a hole or a missing face on one side, or "
          "an extra face on the other); an open interface must end on the same boundary edges on both sides",
          my_side, at(mine, a), at(mine, b),
          other_edges.empty()
              ? fmt::format("where the {}'s interface is closed (it has no boundary edges)", other_side)
              : fmt::format("with no boundary edge of the {}'s interface within {:.3g} (half the element size) of "
                            "{} (the nearest at {:.3g})",
                            other_side, tolerance > 0 ? tolerance : 0.5 * length,
                            fmt::format("({:.6g}, {:.6g}, {:.6g})", p.x(), p.y(), p.z()), best)));
    }
  }
}

}  // namespace

void check_interface_surfaces(const InterfaceMeshData& solid, const InterfaceMeshData& fluid) {
  if (solid.dimension != 3 || fluid.dimension != 3 || solid.faces.empty() || fluid.faces.empty()) return;
  const auto solid_edges = boundary_edges(solid, "solid"), fluid_edges = boundary_edges(fluid, "fluid");
  expect_boundary_on(solid, solid_edges, "solid", fluid, fluid_edges, "fluid");
  expect_boundary_on(fluid, fluid_edges, "fluid", solid, solid_edges, "solid");
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
    check_interface_surfaces(solid, fluid);
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
//   Phi lambda + P a = u,  P^T lambda = 0.
// Coordinates are centred on the solid's nodes and scaled by their bounding-box diagonal L
// (the thin-plate spline's interpolant does not depend on the scale, given the linear term;
// Wendland's radius is scaled with them). The linear terms are taken along the principal
// axes of the solid's nodes, and an axis without extent (nodes on a line) is dropped, as its
// column of P would be zero and the system singular.
//
// The system is solved in the null space of P^T (Householder QR: P = Q1 R, Q = [Q1 Q2]):
// lambda = Q2 mu with K mu = Q2^T u, K = Q2^T Phi Q2 symmetric positive definite (Wendland
// C2 is positive definite, the thin-plate spline conditionally positive definite of order 2:
// positive on the null space of the linear terms), factorised by Cholesky; a = R^-1 Q1^T
// (u - Phi lambda). Evaluated at the fluid's nodes (B = Phi_fs, P_f):
//   H = P_f W + ((B - P_f W Phi) Q2 K^-1) Q2^T,   W = R^-1 Q1^T.
// For u = P c in the span of the linear terms, Q2^T u is zero to round-off, and the second
// term is evaluated in this order ((..) K^-1 first, a matrix of the size of H's entries) so
// that K's conditioning never multiplies that round-off: H reproduces affine fields, and
// H 1 = 1 (forces' sum kept by H^T), to round-off by construction. K is also far better
// conditioned than the whole saddle-point system [Phi P; P^T 0] (Wendland C2 with a support
// of 50 on 1225 nodes of a half cylinder: 6e7 against 1.4e12) and its Cholesky factorisation
// is about a quarter faster than the full-pivoting LU of that system, which reproduced affine
// fields to 1e-14 as well on the meshes measured (docs/fsi3d.md).
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
  const Eigen::Index np = 1 + linear_terms_, m = ns - np;

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
  auto poly = [&](const Points& y) {
    Eigen::MatrixXd p(y.rows(), np);
    p.col(0).setOnes();
    for (int k = 0; k < linear_terms_; ++k) p.col(1 + k) = y * axes[static_cast<std::size_t>(k)];
    return p;
  };
  auto singular = [&](const std::string& why) {
    return std::invalid_argument(
        fmt::format("coupling.mapping {}: the interpolation system on the solid's {} interface nodes is singular ({}: "
                    "coinciding nodes?)",
                    to_string(kind_), ns, why));
  };

  Eigen::MatrixXd phi_ss(ns, ns), phi_fs(nf, ns);
  for (Eigen::Index j = 0; j < ns; ++j) {
    for (Eigen::Index i = 0; i < ns; ++i) phi_ss(i, j) = phi((ys.row(i) - ys.row(j)).norm());
    for (Eigen::Index i = 0; i < nf; ++i) phi_fs(i, j) = phi((yf.row(i) - ys.row(j)).norm());
  }
  const Eigen::MatrixXd ps = poly(ys), pf = poly(yf);
  const Eigen::HouseholderQR<Eigen::MatrixXd> qr(ps);
  const auto r = qr.matrixQR().topLeftCorner(np, np).triangularView<Eigen::Upper>();
  const auto q = qr.householderQ();
  // W = R^-1 Q1^T (np x ns): the least-squares fit of the linear terms.
  Eigen::MatrixXd q1 = Eigen::MatrixXd::Identity(ns, np);
  q1.applyOnTheLeft(q);
  const Eigen::MatrixXd w = r.solve(q1.transpose());
  // K = Q2^T Phi Q2 and E Q2, E = Phi_fs - P_f W Phi: the reflectors applied, no Q formed.
  Eigen::MatrixXd qphiq = phi_ss;
  qphiq.applyOnTheLeft(q.adjoint());
  qphiq.applyOnTheRight(q);
  Eigen::MatrixXd eq = phi_fs - pf * (w * phi_ss);
  eq.applyOnTheRight(q);
  Eigen::MatrixXd hs = pf * w;
  if (m > 0) {
    const Eigen::LLT<Eigen::MatrixXd> llt(qphiq.bottomRightCorner(m, m));
    if (llt.info() != Eigen::Success) throw singular("not positive definite on the null space of the linear terms");
    condition_ = 1.0 / llt.rcond();
    // Cholesky's pivots L_ii^2: one at round-off of the largest is a (numerically) singular K.
    const Eigen::VectorXd d = llt.matrixLLT().diagonal().cwiseAbs2();
    if (!(d.minCoeff() > std::numeric_limits<double>::epsilon() * static_cast<double>(m) * d.maxCoeff()))
      throw singular(fmt::format("condition number {:.3g}", condition_));
    // X = (E Q2) K^-1, then [0 X] Q^T = X Q2^T.
    Eigen::MatrixXd x = Eigen::MatrixXd::Zero(nf, ns);
    x.rightCols(m) = llt.solve(eq.rightCols(m).transpose()).transpose();
    x.applyOnTheRight(q.adjoint());
    hs += x;
  } else {
    condition_ = 1;
  }
  set_from_scalar(hs);
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
