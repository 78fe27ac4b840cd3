#include "fsi/fluid/mesh_motion.hpp"

#include <fmt/format.h>

#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>
#include <chrono>
#include <cmath>
#include <stdexcept>

#include "fsi/common/solver_model.hpp"
#include "fsi/fluid/p1_element.hpp"

namespace fsi::fluid {
namespace {
double now() { return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count(); }
}  // namespace

struct MeshMotion::Impl {
  const FluidMesh* mesh = nullptr;
  MeshMotionOptions options;
  int nodes = 0;
  int comps = 1;  // unknowns per node: 1 (harmonic, per component) or 2 (elastic)
  std::vector<int> moving;
  std::vector<int> free_index;  // node -> free node index or -1 (prescribed)
  int nfree = 0;
  Eigen::SparseMatrix<double> coupling;  // free unknowns x prescribed unknowns (all nodes * comps)
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver;
  bool analysed = false;
  // Incremental state: the mesh of the last accepted step.
  Eigen::MatrixX2d base_displacement;  // n x 2, from the reference
  Eigen::VectorXd base_moving;         // moving nodes' displacement at the base
  double seconds = 0;

  void build(const Eigen::MatrixX2d& positions);
  Eigen::MatrixX2d solve(const Eigen::MatrixX2d& prescribed) const;
};

void MeshMotion::Impl::build(const Eigen::MatrixX2d& positions) {
  const int ne = mesh->triangle_count();
  std::vector<TriangleGeometry> geo(static_cast<std::size_t>(ne));
  double mean_area = 0;
  for (int e = 0; e < ne; ++e) {
    Eigen::Matrix<double, 3, 2> x;
    for (int k = 0; k < 3; ++k) x.row(k) = positions.row(mesh->triangles(e, k));
    geo[static_cast<std::size_t>(e)] = triangle_geometry(x);
    const double area = geo[static_cast<std::size_t>(e)].area;
    if (!(area > 0)) {
      const Eigen::Vector2d c = x.colwise().mean().transpose();
      throw SolverError(
          fmt::format("mesh motion: element {} near ({:.5g}, {:.5g}) is inverted or degenerate "
                      "(area {:.3g}) in the accepted mesh",
                      e, c.x(), c.y(), area));
    }
    mean_area += area / ne;
  }
  const double nu = options.poisson_ratio;
  const double lambda = 2 * nu / (1 - 2 * nu), mu = 1.0;  // scale-free pseudo material
  std::vector<Eigen::Triplet<double>> kff, kfp;
  kff.reserve(static_cast<std::size_t>(ne) * 9 * comps * comps);
  for (int e = 0; e < ne; ++e) {
    const auto& g = geo[static_cast<std::size_t>(e)];
    const double k = g.area * std::pow(mean_area / g.area, options.stiffening);
    for (int a = 0; a < 3; ++a) {
      const int na = mesh->triangles(e, a);
      const int ia = free_index[static_cast<std::size_t>(na)];
      if (ia < 0) continue;
      for (int b = 0; b < 3; ++b) {
        const int nb = mesh->triangles(e, b);
        const int ib = free_index[static_cast<std::size_t>(nb)];
        for (int c = 0; c < comps; ++c)
          for (int d = 0; d < comps; ++d) {
            double v;
            if (comps == 1) {
              v = k * g.grad.row(a).dot(g.grad.row(b));
            } else {
              // Linear elasticity: K_ab^cd = lambda dNa_c dNb_d + mu (dNa_d dNb_c + delta_cd dNa.dNb)
              v = k * (lambda * g.grad(a, c) * g.grad(b, d) + mu * g.grad(a, d) * g.grad(b, c) +
                       (c == d ? mu * g.grad.row(a).dot(g.grad.row(b)) : 0.0));
            }
            if (ib >= 0)
              kff.emplace_back(comps * ia + c, comps * ib + d, v);
            else
              kfp.emplace_back(comps * ia + c, comps * nb + d, v);
          }
      }
    }
  }
  Eigen::SparseMatrix<double> K(comps * nfree, comps * nfree);
  K.setFromTriplets(kff.begin(), kff.end());
  coupling.resize(comps * nfree, comps * nodes);
  coupling.setFromTriplets(kfp.begin(), kfp.end());
  if (nfree > 0) {
    if (!analysed) {
      solver.analyzePattern(K);
      analysed = true;
    }
    solver.factorize(K);
    if (solver.info() != Eigen::Success)
      throw SolverError("mesh motion: factorisation of the extension operator failed");
  }
}

Eigen::MatrixX2d MeshMotion::Impl::solve(const Eigen::MatrixX2d& prescribed) const {
  Eigen::MatrixX2d result = prescribed;
  if (nfree == 0 || prescribed.cwiseAbs().maxCoeff() == 0) return result;
  if (comps == 1) {
    const Eigen::MatrixXd rhs = -(coupling * prescribed);
    const Eigen::MatrixXd free = solver.solve(rhs);
    for (int i = 0; i < nodes; ++i)
      if (const int f = free_index[static_cast<std::size_t>(i)]; f >= 0) result.row(i) = free.row(f);
  } else {
    Eigen::VectorXd p(2 * nodes);
    for (int i = 0; i < nodes; ++i) p.segment<2>(2 * i) = prescribed.row(i).transpose();
    const Eigen::VectorXd free = solver.solve(Eigen::VectorXd(-(coupling * p)));
    for (int i = 0; i < nodes; ++i)
      if (const int f = free_index[static_cast<std::size_t>(i)]; f >= 0)
        result.row(i) = free.segment<2>(2 * f).transpose();
  }
  return result;
}

MeshMotion::MeshMotion(const FluidMesh& mesh, std::vector<int> moving_nodes, std::vector<int> fixed_nodes,
                       MeshMotionOptions options)
    : impl_(std::make_unique<Impl>()) {
  auto& m = *impl_;
  m.mesh = &mesh;
  m.options = options;
  m.nodes = mesh.node_count();
  m.comps = options.method == MeshMotionOptions::Method::Elastic ? 2 : 1;
  m.moving = std::move(moving_nodes);
  std::vector<char> prescribed(static_cast<std::size_t>(m.nodes), 0);
  for (int i : m.moving) prescribed[static_cast<std::size_t>(i)] = 1;
  for (int i : fixed_nodes) prescribed[static_cast<std::size_t>(i)] = 1;
  m.free_index.assign(static_cast<std::size_t>(m.nodes), -1);
  for (int i = 0; i < m.nodes; ++i)
    if (!prescribed[static_cast<std::size_t>(i)]) m.free_index[static_cast<std::size_t>(i)] = m.nfree++;
  m.base_displacement = Eigen::MatrixX2d::Zero(m.nodes, 2);
  m.base_moving = Eigen::VectorXd::Zero(2 * static_cast<Eigen::Index>(m.moving.size()));
  m.build(mesh.nodes);
}

MeshMotion::~MeshMotion() = default;

Eigen::MatrixX2d MeshMotion::extend(const Eigen::VectorXd& moving_displacement) const {
  auto& m = *impl_;
  const double start = now();
  Eigen::MatrixX2d prescribed = Eigen::MatrixX2d::Zero(m.nodes, 2);
  for (std::size_t i = 0; i < m.moving.size(); ++i) {
    const auto k = 2 * static_cast<Eigen::Index>(i);
    prescribed.row(m.moving[i]) = (moving_displacement.segment<2>(k) - m.base_moving.segment<2>(k)).transpose();
  }
  Eigen::MatrixX2d result = m.base_displacement + m.solve(prescribed);
  m.seconds += now() - start;
  return result;
}

void MeshMotion::accept(const Eigen::VectorXd& moving_displacement) {
  auto& m = *impl_;
  if (!m.options.incremental) return;
  const double start = now();
  m.base_displacement = extend(moving_displacement);
  m.base_moving = moving_displacement;
  m.build(m.mesh->nodes + m.base_displacement);
  m.seconds += now() - start;
}

double MeshMotion::seconds() const { return impl_->seconds; }

void MeshMotion::save_state(StateArchive& state, const std::string& prefix) const {
  const auto& m = *impl_;
  state.put(prefix + "base_displacement",
            Eigen::VectorXd(Eigen::Map<const Eigen::VectorXd>(m.base_displacement.data(), m.base_displacement.size())));
  state.put(prefix + "base_moving", m.base_moving);
}

void MeshMotion::load_state(const StateArchive& state, const std::string& prefix) {
  auto& m = *impl_;
  const Eigen::VectorXd base = state.vector(prefix + "base_displacement", 2 * static_cast<Eigen::Index>(m.nodes));
  Eigen::VectorXd moving = state.vector(prefix + "base_moving", m.base_moving.size());
  const double start = now();
  m.base_displacement = Eigen::Map<const Eigen::MatrixX2d>(base.data(), m.nodes, 2);
  m.base_moving = std::move(moving);
  if (m.options.incremental) m.build(m.mesh->nodes + m.base_displacement);
  m.seconds += now() - start;
}

}  // namespace fsi::fluid
