#include "fsi/fluid/mesh_motion.hpp"

#include <fmt/format.h>

#include <Eigen/LU>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>
#include <chrono>
#include <cmath>
#include <memory>
#include <stdexcept>

#include "fsi/common/solver_model.hpp"
#include "fsi/fluid/p1_element.hpp"

namespace fsi::fluid {
namespace {
double now() { return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count(); }

// The element plug-in: the linear cells (triangles / tetrahedra) on the vertices, their
// measure and P1 shape-function gradients, and how an inverted one is named.
template <int Dim>
struct Cell;

template <>
struct Cell<2> {
  static constexpr int kNodes = 3;
  struct Geometry {
    double measure = 0;
    Eigen::Matrix<double, 3, 2> grad;
  };
  static const IndexMatrix3& cells(const FluidMesh& mesh) { return mesh.triangles; }
  static Geometry geometry(const Eigen::Matrix<double, 3, 2>& x) {
    const TriangleGeometry g = triangle_geometry(x);
    return {g.area, g.grad};
  }
  static std::string inverted(int e, const Eigen::Matrix<double, 3, 2>& x, double measure) {
    const Eigen::Vector2d c = x.colwise().mean().transpose();
    return fmt::format(
        "mesh motion: element {} near ({:.5g}, {:.5g}) is inverted or degenerate "
        "(area {:.3g}) in the accepted mesh",
        e, c.x(), c.y(), measure);
  }
};

template <>
struct Cell<3> {
  static constexpr int kNodes = 4;
  struct Geometry {
    double measure = 0;
    Eigen::Matrix<double, 4, 3> grad = Eigen::Matrix<double, 4, 3>::Zero();
  };
  static const IndexMatrix4& cells(const TetMesh& mesh) { return mesh.tets; }
  static Geometry geometry(const Eigen::Matrix<double, 4, 3>& x) {
    Geometry g;
    Eigen::Matrix3d J;  // columns: the edges from vertex 0
    for (int k = 0; k < 3; ++k) J.col(k) = (x.row(k + 1) - x.row(0)).transpose();
    const double det = J.determinant();
    g.measure = det / 6.0;
    if (det == 0) return g;
    const Eigen::Matrix3d inv = J.inverse();  // row k: grad N_{k+1}
    g.grad.bottomRows<3>() = inv;
    g.grad.row(0) = -inv.colwise().sum();
    return g;
  }
  static std::string inverted(int e, const Eigen::Matrix<double, 4, 3>& x, double measure) {
    const Eigen::Vector3d c = x.colwise().mean().transpose();
    return fmt::format(
        "mesh motion: tetrahedron {} near ({:.5g}, {:.5g}, {:.5g}) is inverted or degenerate "
        "(volume {:.3g}) in the accepted mesh",
        e, c.x(), c.y(), c.z(), measure);
  }
};

}  // namespace

template <int Dim>
struct BasicMeshMotion<Dim>::Impl {
  using Mesh = typename BasicMeshMotion<Dim>::Mesh;
  using Nodes = typename BasicMeshMotion<Dim>::Nodes;
  static constexpr int kCellNodes = Cell<Dim>::kNodes;
  const Mesh* mesh = nullptr;
  MeshMotionOptions options;
  int nodes = 0;
  int comps = 1;  // unknowns per node: 1 (harmonic, per component) or Dim (elastic)
  std::vector<int> moving;
  std::vector<char> prescribed;  // per node: moving or fixed
  std::vector<int> free_index;   // node -> free vertex index or -1 (prescribed, or an edge midpoint)
  int nfree = 0;
  Eigen::SparseMatrix<double> coupling;  // free unknowns x prescribed unknowns (all nodes * comps)
  using Factor = Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>>;
  std::shared_ptr<Factor> solver = std::make_shared<Factor>();  // shared with a snapshot until the next build
  bool analysed = false;
  // Incremental state: the mesh of the last accepted step.
  Nodes base_displacement;      // n x Dim, from the reference
  Eigen::VectorXd base_moving;  // moving nodes' displacement at the base
  double seconds = 0;

  void build(const Nodes& positions);
  Nodes solve(const Nodes& prescribed_values) const;
};

template <int Dim>
void BasicMeshMotion<Dim>::Impl::build(const Nodes& positions) {
  using Geometry = typename Cell<Dim>::Geometry;
  const auto& cells = Cell<Dim>::cells(*mesh);
  const int ne = mesh->cell_count();
  std::vector<Geometry> geo(static_cast<std::size_t>(ne));
  double mean_area = 0;
  for (int e = 0; e < ne; ++e) {
    Eigen::Matrix<double, kCellNodes, Dim> x;
    for (int k = 0; k < kCellNodes; ++k) x.row(k) = positions.row(cells(e, k));
    geo[static_cast<std::size_t>(e)] = Cell<Dim>::geometry(x);
    const double area = geo[static_cast<std::size_t>(e)].measure;
    if (!(area > 0)) throw SolverError(Cell<Dim>::inverted(e, x, area));
    mean_area += area / ne;
  }
  const double nu = options.poisson_ratio;
  const double lambda = 2 * nu / (1 - 2 * nu), mu = 1.0;  // scale-free pseudo material
  std::vector<Eigen::Triplet<double>> kff, kfp;
  kff.reserve(static_cast<std::size_t>(ne) * kCellNodes * kCellNodes * comps * comps);
  for (int e = 0; e < ne; ++e) {
    const auto& g = geo[static_cast<std::size_t>(e)];
    const double k = g.measure * std::pow(mean_area / g.measure, options.stiffening);
    for (int a = 0; a < kCellNodes; ++a) {
      const int na = cells(e, a);
      const int ia = free_index[static_cast<std::size_t>(na)];
      if (ia < 0) continue;
      for (int b = 0; b < kCellNodes; ++b) {
        const int nb = cells(e, b);
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
    if (solver.use_count() > 1) {  // a snapshot holds these factors: factorise into new ones
      solver = std::make_shared<Factor>();
      analysed = false;
    }
    if (!analysed) {
      solver->analyzePattern(K);
      analysed = true;
    }
    solver->factorize(K);
    if (solver->info() != Eigen::Success)
      throw SolverError("mesh motion: factorisation of the extension operator failed");
  }
}

template <int Dim>
auto BasicMeshMotion<Dim>::Impl::solve(const Nodes& prescribed_values) const -> Nodes {
  Nodes result = prescribed_values;
  if (nfree > 0 && prescribed_values.cwiseAbs().maxCoeff() != 0) {
    if (comps == 1) {
      const Eigen::MatrixXd rhs = -(coupling * prescribed_values);
      const Eigen::MatrixXd free = solver->solve(rhs);
      for (int i = 0; i < nodes; ++i)
        if (const int f = free_index[static_cast<std::size_t>(i)]; f >= 0) result.row(i) = free.row(f);
    } else {
      Eigen::VectorXd p(Dim * nodes);
      for (int i = 0; i < nodes; ++i) p.template segment<Dim>(Dim * i) = prescribed_values.row(i).transpose();
      const Eigen::VectorXd free = solver->solve(Eigen::VectorXd(-(coupling * p)));
      for (int i = 0; i < nodes; ++i)
        if (const int f = free_index[static_cast<std::size_t>(i)]; f >= 0)
          result.row(i) = free.template segment<Dim>(Dim * f).transpose();
    }
  }
  if (mesh->quadratic()) {  // midpoints neither moving nor fixed: the mean of their edge's vertices
    Nodes interpolated = result;
    mesh->interpolate_midpoints(interpolated);
    for (int i = mesh->vertices(); i < nodes; ++i)
      if (!prescribed[static_cast<std::size_t>(i)]) result.row(i) = interpolated.row(i);
  }
  return result;
}

template <int Dim>
BasicMeshMotion<Dim>::BasicMeshMotion(const Mesh& mesh, std::vector<int> moving_nodes, std::vector<int> fixed_nodes,
                                      MeshMotionOptions options)
    : impl_(std::make_unique<Impl>()) {
  auto& m = *impl_;
  m.mesh = &mesh;
  m.options = options;
  m.nodes = mesh.node_count();
  m.comps = options.method == MeshMotionOptions::Method::Elastic ? Dim : 1;
  m.moving = std::move(moving_nodes);
  m.prescribed.assign(static_cast<std::size_t>(m.nodes), 0);
  for (int i : m.moving) m.prescribed.at(static_cast<std::size_t>(i)) = 1;
  for (int i : fixed_nodes) m.prescribed.at(static_cast<std::size_t>(i)) = 1;
  m.free_index.assign(static_cast<std::size_t>(m.nodes), -1);
  const int vertices = mesh.vertices();  // the extension's unknowns: the free vertices
  for (int i = 0; i < vertices; ++i)
    if (!m.prescribed[static_cast<std::size_t>(i)]) m.free_index[static_cast<std::size_t>(i)] = m.nfree++;
  m.base_displacement = Nodes::Zero(m.nodes, Dim);
  m.base_moving = Eigen::VectorXd::Zero(Dim * static_cast<Eigen::Index>(m.moving.size()));
  m.build(mesh.nodes);
}

template <int Dim>
BasicMeshMotion<Dim>::~BasicMeshMotion() = default;

template <int Dim>
auto BasicMeshMotion<Dim>::extend(const Eigen::VectorXd& moving_displacement) const -> Nodes {
  auto& m = *impl_;
  if (moving_displacement.size() != m.base_moving.size())
    throw std::invalid_argument(fmt::format("mesh motion: {} moving-node displacements for {} moving nodes ({}D)",
                                            moving_displacement.size(), m.moving.size(), Dim));
  const double start = now();
  Nodes prescribed = Nodes::Zero(m.nodes, Dim);
  for (std::size_t i = 0; i < m.moving.size(); ++i) {
    const auto k = Dim * static_cast<Eigen::Index>(i);
    prescribed.row(m.moving[i]) =
        (moving_displacement.template segment<Dim>(k) - m.base_moving.template segment<Dim>(k)).transpose();
  }
  Nodes result = m.base_displacement + m.solve(prescribed);
  m.seconds += now() - start;
  return result;
}

template <int Dim>
auto BasicMeshMotion<Dim>::positions(const Eigen::VectorXd& moving_displacement) const -> Nodes {
  return impl_->mesh->nodes + extend(moving_displacement);
}

template <int Dim>
void BasicMeshMotion<Dim>::accept(const Eigen::VectorXd& moving_displacement) {
  auto& m = *impl_;
  if (!m.options.incremental) return;
  const double start = now();
  m.base_displacement = extend(moving_displacement);
  m.base_moving = moving_displacement;
  m.build(m.mesh->nodes + m.base_displacement);
  m.seconds += now() - start;
}

template <int Dim>
double BasicMeshMotion<Dim>::seconds() const {
  return impl_->seconds;
}

template <int Dim>
const std::vector<int>& BasicMeshMotion<Dim>::moving_nodes() const {
  return impl_->moving;
}

template <int Dim>
void BasicMeshMotion<Dim>::save_state(StateArchive& state, const std::string& prefix) const {
  const auto& m = *impl_;
  state.put(prefix + "base_displacement",
            Eigen::VectorXd(Eigen::Map<const Eigen::VectorXd>(m.base_displacement.data(), m.base_displacement.size())));
  state.put(prefix + "base_moving", m.base_moving);
}

template <int Dim>
void BasicMeshMotion<Dim>::load_state(const StateArchive& state, const std::string& prefix) {
  auto& m = *impl_;
  const Eigen::VectorXd base = state.vector(prefix + "base_displacement", Dim * static_cast<Eigen::Index>(m.nodes));
  Eigen::VectorXd moving = state.vector(prefix + "base_moving", m.base_moving.size());
  const double start = now();
  m.base_displacement = Eigen::Map<const Nodes>(base.data(), m.nodes, Dim);
  m.base_moving = std::move(moving);
  if (m.options.incremental) m.build(m.mesh->nodes + m.base_displacement);
  m.seconds += now() - start;
}

template <int Dim>
struct BasicMeshMotion<Dim>::Snapshot {
  Nodes base_displacement;
  Eigen::VectorXd base_moving;
  Eigen::SparseMatrix<double> coupling;
  std::shared_ptr<typename Impl::Factor> solver;
  bool analysed = false;
};

template <int Dim>
auto BasicMeshMotion<Dim>::snapshot() const -> std::shared_ptr<const Snapshot> {
  const auto& m = *impl_;
  auto s = std::make_shared<Snapshot>();
  s->base_displacement = m.base_displacement;
  s->base_moving = m.base_moving;
  if (m.options.incremental) s->coupling = m.coupling, s->solver = m.solver, s->analysed = m.analysed;
  return s;
}

template <int Dim>
void BasicMeshMotion<Dim>::restore(const Snapshot& s) {
  auto& m = *impl_;
  m.base_displacement = s.base_displacement;
  m.base_moving = s.base_moving;
  if (m.options.incremental) m.coupling = s.coupling, m.solver = s.solver, m.analysed = s.analysed;
}

template class BasicMeshMotion<2>;
template class BasicMeshMotion<3>;

}  // namespace fsi::fluid
