#include "fsi/fluid/mesh_motion.hpp"

#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>

#include <cmath>
#include <stdexcept>

#include "fsi/fluid/p1_element.hpp"

namespace fsi::fluid {

struct MeshMotion::Impl {
  int nodes = 0;
  std::vector<int> moving;
  std::vector<int> free_index;          // node -> unknown index or -1 (prescribed)
  Eigen::SparseMatrix<double> coupling;  // free rows x prescribed (all nodes) columns
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver;
};

MeshMotion::MeshMotion(const FluidMesh& mesh, std::vector<int> moving_nodes, std::vector<int> fixed_nodes, double stiffening)
    : impl_(std::make_unique<Impl>()) {
  const int n = mesh.node_count();
  impl_->nodes = n;
  impl_->moving = std::move(moving_nodes);
  std::vector<char> prescribed(static_cast<std::size_t>(n), 0);
  for (int i : impl_->moving) prescribed[static_cast<std::size_t>(i)] = 1;
  for (int i : fixed_nodes) prescribed[static_cast<std::size_t>(i)] = 1;
  impl_->free_index.assign(static_cast<std::size_t>(n), -1);
  int nfree = 0;
  for (int i = 0; i < n; ++i)
    if (!prescribed[static_cast<std::size_t>(i)]) impl_->free_index[static_cast<std::size_t>(i)] = nfree++;
  double mean_area = 0;
  std::vector<TriangleGeometry> geo(static_cast<std::size_t>(mesh.triangle_count()));
  for (int e = 0; e < mesh.triangle_count(); ++e) {
    Eigen::Matrix<double, 3, 2> x;
    for (int k = 0; k < 3; ++k) x.row(k) = mesh.nodes.row(mesh.triangles(e, k));
    geo[static_cast<std::size_t>(e)] = triangle_geometry(x);
    mean_area += geo[static_cast<std::size_t>(e)].area / mesh.triangle_count();
  }
  std::vector<Eigen::Triplet<double>> kff, kfp;
  for (int e = 0; e < mesh.triangle_count(); ++e) {
    const auto& g = geo[static_cast<std::size_t>(e)];
    const double k = g.area * std::pow(mean_area / g.area, stiffening);
    for (int a = 0; a < 3; ++a) {
      const int ia = impl_->free_index[static_cast<std::size_t>(mesh.triangles(e, a))];
      if (ia < 0) continue;
      for (int b = 0; b < 3; ++b) {
        const double v = k * g.grad.row(a).dot(g.grad.row(b));
        const int nb = mesh.triangles(e, b);
        const int ib = impl_->free_index[static_cast<std::size_t>(nb)];
        if (ib >= 0) kff.emplace_back(ia, ib, v);
        else kfp.emplace_back(ia, nb, v);
      }
    }
  }
  Eigen::SparseMatrix<double> K(nfree, nfree);
  K.setFromTriplets(kff.begin(), kff.end());
  impl_->coupling.resize(nfree, n);
  impl_->coupling.setFromTriplets(kfp.begin(), kfp.end());
  if (nfree > 0) {
    impl_->solver.compute(K);
    if (impl_->solver.info() != Eigen::Success) throw std::runtime_error("mesh motion: Laplace matrix factorisation failed");
  }
}

MeshMotion::~MeshMotion() = default;

Eigen::MatrixX2d MeshMotion::extend(const Eigen::VectorXd& moving_displacement) const {
  const int n = impl_->nodes;
  Eigen::MatrixX2d prescribed = Eigen::MatrixX2d::Zero(n, 2);
  for (std::size_t i = 0; i < impl_->moving.size(); ++i)
    prescribed.row(impl_->moving[i]) = moving_displacement.segment<2>(2 * static_cast<Eigen::Index>(i)).transpose();
  Eigen::MatrixX2d result = prescribed;
  if (impl_->coupling.rows() == 0 || moving_displacement.size() == 0 || moving_displacement.cwiseAbs().maxCoeff() == 0)
    return result;
  const Eigen::MatrixXd rhs = -(impl_->coupling * prescribed);
  const Eigen::MatrixXd free = impl_->solver.solve(rhs);
  for (int i = 0; i < n; ++i) {
    const int f = impl_->free_index[static_cast<std::size_t>(i)];
    if (f >= 0) result.row(i) = free.row(f);
  }
  return result;
}

}  // namespace fsi::fluid
