#include "fsi/coupling/interface_map.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

namespace fsi::coupling {

InterfaceMap::InterfaceMap(const InterfaceMeshData& solid, const InterfaceMeshData& fluid) {
  const Eigen::Index ns = solid.coordinates.rows(), nf = fluid.coordinates.rows();
  if (ns == 0 && nf == 0) {
    h_.resize(0, 0);
    ht_.resize(0, 0);
    hs_.resize(0, 0);
    hst_.resize(0, 0);
    return;
  }
  if (ns == 0 || nf == 0)
    throw std::invalid_argument(fmt::format("interface mismatch: the solid has {} interface nodes, the fluid {}", ns, nf));
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

  detect_conforming(solid, fluid);
}

// Conforming? The nearest solid node of every fluid node (detection only: H stays the
// projection above, which for coinciding nodes is P to round-off).
void InterfaceMap::detect_conforming(const InterfaceMeshData& solid, const InterfaceMeshData& fluid) {
  const Eigen::Index ns = solid.coordinates.rows(), nf = fluid.coordinates.rows();
  Eigen::Vector2d lo = solid.coordinates.colwise().minCoeff().transpose();
  Eigen::Vector2d hi = solid.coordinates.colwise().maxCoeff().transpose();
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
    throw std::invalid_argument(fmt::format("interface mass of the fluid is {} x {}, expected {} x {} (its interface nodes)",
                                            fluid_mass.rows(), fluid_mass.cols(), hs_.rows(), hs_.rows()));
  NodalMatrix m = hst_ * fluid_mass * hs_;
  m.makeCompressed();
  return m;
}

NodalMatrix nodal_interface_mass(const InterfaceMeshData& solid, const Eigen::VectorXd& displacement) {
  const Eigen::Index n = solid.coordinates.rows();
  std::vector<Eigen::Triplet<double>> t;
  if (solid.segments.empty()) {
    for (Eigen::Index i = 0; i < n; ++i) t.emplace_back(i, i, solid.lumped_measure[i]);
  } else {
    auto x = [&](int i) {
      Eigen::Vector2d p = solid.coordinates.row(i).transpose();
      if (displacement.size() == 2 * n) p += displacement.segment<2>(2 * i);
      return p;
    };
    for (const auto& seg : solid.segments) {
      const double len = (x(seg[1]) - x(seg[0])).norm();
      t.emplace_back(seg[0], seg[0], len / 3);
      t.emplace_back(seg[1], seg[1], len / 3);
      t.emplace_back(seg[0], seg[1], len / 6);
      t.emplace_back(seg[1], seg[0], len / 6);
    }
  }
  NodalMatrix m(n, n);
  m.setFromTriplets(t.begin(), t.end());
  return m;
}

Eigen::SparseMatrix<double> interface_mass(const InterfaceMeshData& solid, const Eigen::VectorXd& displacement) {
  // The nodal mass acting on both components: (M (x) I_2).
  const NodalMatrix nodal = nodal_interface_mass(solid, displacement);
  std::vector<Eigen::Triplet<double>> t;
  t.reserve(2 * static_cast<std::size_t>(nodal.nonZeros()));
  for (int col = 0; col < nodal.outerSize(); ++col)
    for (NodalMatrix::InnerIterator it(nodal, col); it; ++it)
      for (int c = 0; c < 2; ++c) t.emplace_back(2 * it.row() + c, 2 * it.col() + c, it.value());
  Eigen::SparseMatrix<double> m(2 * nodal.rows(), 2 * nodal.cols());
  m.setFromTriplets(t.begin(), t.end());
  return m;
}

}  // namespace fsi::coupling
