#include "fsi/fluid/taylor_hood_solver.hpp"

#include <Eigen/LU>
#include <Eigen/SparseCore>
#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <limits>
#include <map>

#include "fsi/common/solver_model.hpp"
#include "fsi/fluid/p2p1_element.hpp"
#include "fsi/fluid/sparse_lu.hpp"
#include "flow_common.hpp"

#ifdef _OPENMP
#include <omp.h>
#endif

namespace fsi::fluid {
namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

// A boundary edge on the Nitsche interface: its triangle, the local edge k (vertices k, k+1,
// midpoint 3 + k) and the interface indices of those three nodes.
struct InterfaceEdge {
  int element;
  int edge;
  std::array<int, 3> iface;  // vertex k, vertex k+1, midpoint
};

constexpr int kEdgeNodes[3][3] = {{0, 1, 3}, {1, 2, 4}, {2, 0, 5}};
const Eigen::Vector2d kRefVertex[3] = {{0, 0}, {1, 0}, {0, 1}};
// 4-point Gauss-Legendre on [0, 1].
constexpr double kGaussX[4] = {0.0694318442029737, 0.3300094782075719, 0.6699905217924281, 0.9305681557970263};
constexpr double kGaussW[4] = {0.1739274225687269, 0.3260725774312731, 0.3260725774312731, 0.1739274225687269};

// Geometry at point s of edge k of an element: shape functions, physical gradients, the
// length element and the outward normal.
struct EdgePoint {
  Eigen::Matrix<double, 6, 1> N;
  Eigen::Matrix<double, 6, 2> G;
  double ds = 0;
  Eigen::Vector2d normal;
  Eigen::Vector3d L;  // linear (pressure) shape functions
};

EdgePoint edge_point(const Eigen::Matrix<double, 6, 2>& x, int k, double s) {
  EdgePoint p;
  const Eigen::Vector2d d = kRefVertex[(k + 1) % 3] - kRefVertex[k];
  const Eigen::Vector2d r = kRefVertex[k] + s * d;
  Eigen::Matrix<double, 6, 2> dN;
  p2_shape(r.x(), r.y(), p.N, dN);
  const Eigen::Matrix2d J = x.transpose() * dN;
  p.G = dN * J.inverse();
  const Eigen::Vector2d t = J * d;
  p.ds = t.norm();
  p.normal = Eigen::Vector2d(t.y(), -t.x()) / p.ds;  // counter-clockwise element: outward
  p.L << 1 - r.x() - r.y(), r.x(), r.y();
  return p;
}

}  // namespace

struct TaylorHoodSolver::Impl {
  Eigen::SparseMatrix<double> matrix, volume;
  std::vector<int> scatter;  // per element 15 x 15 positions in valuePtr (column-major local)
  std::unique_ptr<SparseLu> lu;
  std::vector<detail::DirichletCondition> dirichlet;
  std::vector<detail::SymmetryCondition> symmetry;
  std::vector<InterfaceEdge> edges;
  int pressure_vertex = -1;
  std::function<double(double)> pressure_value;
  VelocityFunction body_force;
  std::vector<std::vector<double>> thread_values;
  Eigen::VectorXd last_rhs;
  int n = 0, nv = 0;
  std::array<int, 15> element_dofs(const FluidMesh& m, int e) const {
    std::array<int, 15> d{};
    const auto nodes = m.element_nodes6(e);
    for (int k = 0; k < 6; ++k) {
      d[static_cast<std::size_t>(2 * k)] = 2 * nodes(k);
      d[static_cast<std::size_t>(2 * k + 1)] = 2 * nodes(k) + 1;
    }
    for (int k = 0; k < 3; ++k) d[static_cast<std::size_t>(12 + k)] = 2 * n + nodes(k);
    return d;
  }
};

TaylorHoodSolver::TaylorHoodSolver(FluidMesh mesh, FlowParameters params)
    : mesh_(mesh.quadratic() ? std::move(mesh) : mesh.quadratic_from_linear()),
      params_(params),
      impl_(std::make_unique<Impl>()) {
  auto& im = *impl_;
  im.n = mesh_.node_count();
  im.nv = mesh_.vertices();
  im.lu = std::make_unique<SparseLu>(params_);
  const int ndof = dofs();
  const int ne = mesh_.triangle_count();
  // Sparsity: per column the sorted rows coupled to it by some element.
  std::vector<std::vector<int>> rows(static_cast<std::size_t>(ndof));
  for (int e = 0; e < ne; ++e) {
    const auto d = im.element_dofs(mesh_, e);
    for (int c : d)
      for (int r : d) rows[static_cast<std::size_t>(c)].push_back(r);
  }
  std::size_t nnz = 0;
  for (auto& list : rows) {
    std::sort(list.begin(), list.end());
    list.erase(std::unique(list.begin(), list.end()), list.end());
    nnz += list.size();
  }
  auto& A = im.matrix;
  A.resize(ndof, ndof);
  A.resizeNonZeros(static_cast<Eigen::Index>(nnz));
  int pos = 0;
  for (int c = 0; c < ndof; ++c) {
    A.outerIndexPtr()[c] = pos;
    for (int r : rows[static_cast<std::size_t>(c)]) A.innerIndexPtr()[pos++] = r;
  }
  A.outerIndexPtr()[ndof] = pos;
  std::fill(A.valuePtr(), A.valuePtr() + nnz, 0.0);
  im.volume = A;
  im.scatter.resize(static_cast<std::size_t>(ne) * 225);
  for (int e = 0; e < ne; ++e) {
    const auto d = im.element_dofs(mesh_, e);
    for (int j = 0; j < 15; ++j) {
      const auto& list = rows[static_cast<std::size_t>(d[static_cast<std::size_t>(j)])];
      for (int i = 0; i < 15; ++i) {
        const auto it = std::lower_bound(list.begin(), list.end(), d[static_cast<std::size_t>(i)]);
        im.scatter[static_cast<std::size_t>(e) * 225 + static_cast<std::size_t>(15 * j + i)] =
            A.outerIndexPtr()[d[static_cast<std::size_t>(j)]] + static_cast<int>(it - list.begin());
      }
    }
  }
  U_ = U_n_ = U_nm1_ = reaction_ = Eigen::VectorXd::Zero(ndof);
  X_ = X_n_ = X_nm1_ = mesh_.nodes;
  interface_segments_.resize(0, 2);
  // Curved elements must map validly before anything moves.
  for (int e = 0; e < ne; ++e) {
    Eigen::Matrix<double, 6, 2> x;
    const auto nodes = mesh_.element_nodes6(e);
    for (int k = 0; k < 6; ++k) x.row(k) = mesh_.nodes.row(nodes(k));
    if (!(p2_min_jacobian(x) > 0)) {
      const Eigen::RowVector2d c = (x.row(0) + x.row(1) + x.row(2)) / 3.0;
      throw std::invalid_argument(fmt::format("fluid mesh: 6-node triangle {} near ({:.5g}, {:.5g}) is inverted or too "
                                              "strongly curved (det J <= 0 inside)",
                                              e, c(0), c(1)));
    }
  }
}

TaylorHoodSolver::~TaylorHoodSolver() = default;
TaylorHoodSolver::TaylorHoodSolver(TaylorHoodSolver&&) noexcept = default;
TaylorHoodSolver& TaylorHoodSolver::operator=(TaylorHoodSolver&&) noexcept = default;

void TaylorHoodSolver::add_dirichlet(const std::string& group, VelocityFunction velocity) {
  impl_->dirichlet.push_back({mesh_.boundary_nodes({group}), std::move(velocity)});
}

void TaylorHoodSolver::add_symmetry(const std::string& group) {
  impl_->symmetry.push_back({mesh_.boundary_nodes({group}), detail::symmetry_component(mesh_, group)});
}

void TaylorHoodSolver::set_interface(const std::vector<std::string>& groups) {
  interface_nodes_ = mesh_.boundary_nodes(groups);
  std::map<int, int> local;
  for (std::size_t i = 0; i < interface_nodes_.size(); ++i) local[interface_nodes_[i]] = static_cast<int>(i);
  std::map<std::pair<int, int>, std::pair<int, int>> edge_owner;  // vertex pair -> (element, edge)
  for (int e = 0; e < mesh_.triangle_count(); ++e)
    for (int k = 0; k < 3; ++k) {
      const int a = mesh_.triangles(e, k), b = mesh_.triangles(e, (k + 1) % 3);
      edge_owner[{std::min(a, b), std::max(a, b)}] = {e, k};
    }
  impl_->edges.clear();
  std::vector<std::array<int, 2>> segs;
  for (const auto& name : groups) {
    const auto& seg = mesh_.boundary(name);
    for (Eigen::Index s = 0; s < seg.rows(); ++s) {
      const int a = seg(s, 0), b = seg(s, 1);
      const auto it = edge_owner.find({std::min(a, b), std::max(a, b)});
      if (it == edge_owner.end())
        throw std::runtime_error(fmt::format("interface group '{}': segment ({}, {}) is not a triangle edge", name, a, b));
      InterfaceEdge ie{};
      ie.element = it->second.first;
      ie.edge = it->second.second;
      const auto nodes = mesh_.element_nodes6(ie.element);
      for (int j = 0; j < 3; ++j) ie.iface[static_cast<std::size_t>(j)] = local.at(nodes(kEdgeNodes[ie.edge][j]));
      impl_->edges.push_back(ie);
      segs.push_back({ie.iface[0], ie.iface[2]});
      segs.push_back({ie.iface[2], ie.iface[1]});
    }
  }
  interface_segments_.resize(static_cast<Eigen::Index>(segs.size()), 2);
  for (std::size_t s = 0; s < segs.size(); ++s) interface_segments_.row(static_cast<Eigen::Index>(s)) << segs[s][0], segs[s][1];
  interface_velocity_ = Eigen::VectorXd::Zero(2 * static_cast<Eigen::Index>(interface_nodes_.size()));
}

void TaylorHoodSolver::set_pressure_reference(const Eigen::Vector2d& point, std::function<double(double)> value) {
  Eigen::Index best = 0;
  (mesh_.nodes.topRows(mesh_.vertices()).rowwise() - point.transpose()).rowwise().squaredNorm().minCoeff(&best);
  impl_->pressure_vertex = static_cast<int>(best);
  impl_->pressure_value = std::move(value);
}

void TaylorHoodSolver::set_body_force(VelocityFunction force) { impl_->body_force = std::move(force); }

void TaylorHoodSolver::set_initial_velocity(const Eigen::MatrixX2d& velocity) {
  for (int i = 0; i < mesh_.node_count(); ++i)
    for (int c = 0; c < 2; ++c) U_n_(2 * i + c) = U_nm1_(2 * i + c) = U_(2 * i + c) = velocity(i, c);
}

StepReport TaylorHoodSolver::solve(double time, double dt, const Eigen::MatrixX2d& positions,
                                   const Eigen::VectorXd& interface_velocity) {
  StepReport report;
  auto& im = *impl_;
  const int n = mesh_.node_count(), ndof = dofs(), ne = mesh_.triangle_count();
  if (positions.rows() != n) throw std::invalid_argument("TaylorHoodSolver::solve: positions has the wrong size");
  X_ = positions;
  dt_trial_ = dt;
  if (interface_velocity.size() == 0) interface_velocity_.setZero();
  else if (interface_velocity.size() != 2 * static_cast<Eigen::Index>(interface_nodes_.size()))
    throw std::invalid_argument(fmt::format("interface velocity has {} entries, expected {}", interface_velocity.size(),
                                            2 * interface_nodes_.size()));
  else interface_velocity_ = interface_velocity;

  const bool steady = params_.scheme == TimeScheme::Steady;
  const auto [alpha0, alpha1, alpha2, extrap] = detail::bdf_coefficients(params_.scheme, accepted_, dt, dt_n_);
  Eigen::MatrixX2d mesh_velocity = Eigen::MatrixX2d::Zero(n, 2);
  if (!steady) mesh_velocity = (alpha0 * X_ + alpha1 * X_n_ + alpha2 * X_nm1_) / dt;
  Eigen::VectorXd U_lin = steady ? U_n_ : Eigen::VectorXd((1 + extrap) * U_n_ - extrap * U_nm1_);
  // A later coupling iteration of the step starts its linear solve from the last iterate's
  // solution (closer than the extrapolation; the system solved is the same).
  const bool retrial = trial_solves_ > 0 && U_.size() == U_lin.size();
  if (params_.relinearise && trial_solves_ > 0) U_lin = U_;  // a coupling iteration: about the last iterate
  ++trial_solves_;
  Eigen::VectorXd history = Eigen::VectorXd::Zero(ndof);
  if (!steady) history = (alpha1 * U_n_ + alpha2 * U_nm1_) / dt;

  const auto constraints = detail::strong_constraints(ndof, im.dirichlet, im.symmetry, X_, time,
                                                      [](int i, int c) { return 2 * i + c; },
                                                      im.pressure_vertex >= 0 ? 2 * n + im.pressure_vertex : -1, im.pressure_value ? im.pressure_value(time) : 0.0);
  Eigen::MatrixX2d body = Eigen::MatrixX2d::Zero(n, 2);
  if (im.body_force)
    for (int i = 0; i < n; ++i) body.row(i) = im.body_force(X_.row(i).transpose(), time).transpose();

  auto& A = im.matrix;
  auto& V = im.volume;
  const std::size_t nnz = static_cast<std::size_t>(A.nonZeros());
  const int nthreads = std::max(1, params_.threads);
  im.thread_values.resize(static_cast<std::size_t>(nthreads));
  Eigen::VectorXd rhs(ndof), rhs_volume(ndof);
  double previous_change = std::numeric_limits<double>::infinity();

  for (int iteration = 1; iteration <= std::max(1, params_.max_iterations); ++iteration) {
    const auto t_assembly = Clock::now();
    std::vector<Eigen::VectorXd> thread_rhs(static_cast<std::size_t>(nthreads), Eigen::VectorXd::Zero(ndof));
    int bad_element = -1;
    double bad_det = 0;
#pragma omp parallel num_threads(nthreads)
    {
#ifdef _OPENMP
      const int tid = omp_get_thread_num();
#else
      const int tid = 0;
#endif
      auto& values = im.thread_values[static_cast<std::size_t>(tid)];
      values.assign(nnz, 0.0);
      auto& b = thread_rhs[static_cast<std::size_t>(tid)];
      P2ElementInput in;
      P2ElementOutput out;
      in.density = params_.density;
      in.viscosity = params_.viscosity;
      in.alpha0_dt = steady ? 0.0 : alpha0 / dt;
      in.dt = steady ? 0.0 : dt;
      in.newton = params_.newton;
#pragma omp for schedule(static)
      for (int e = 0; e < ne; ++e) {
        const auto nodes = mesh_.element_nodes6(e);
        for (int k = 0; k < 6; ++k) {
          const int node = nodes(k);
          in.x.row(k) = X_.row(node);
          for (int c = 0; c < 2; ++c) {
            in.velocity(k, c) = U_lin(2 * node + c);
            in.advection(k, c) = U_lin(2 * node + c) - mesh_velocity(node, c);
            in.history(k, c) = history(2 * node + c);
          }
          in.force.row(k) = body.row(node);
        }
        if (!assemble_p2p1_element(in, params_.stabilisation, out)) {
#pragma omp critical
          {
            bad_element = e;
            bad_det = out.min_jacobian;
          }
          continue;
        }
        const int* sc = &im.scatter[static_cast<std::size_t>(e) * 225];
        for (int j = 0; j < 15; ++j)
          for (int i = 0; i < 15; ++i) values[static_cast<std::size_t>(sc[15 * j + i])] += out.matrix(i, j);
        const auto d = im.element_dofs(mesh_, e);
        for (int i = 0; i < 15; ++i) b(d[static_cast<std::size_t>(i)]) += out.rhs(i);
      }
    }
    if (bad_element >= 0) {
      const Eigen::RowVector2d centre = (X_.row(mesh_.triangles(bad_element, 0)) + X_.row(mesh_.triangles(bad_element, 1)) +
                                         X_.row(mesh_.triangles(bad_element, 2))) / 3.0;
      throw SolverError(fmt::format("fluid step at t = {:.6g}: 6-node element {} near ({:.5g}, {:.5g}) is inverted or too "
                                    "strongly curved (det J = {:.3g}); the mesh motion tangled the mesh",
                                    time, bad_element, centre(0), centre(1), bad_det));
    }
    double* vv = V.valuePtr();
    std::copy(im.thread_values[0].begin(), im.thread_values[0].end(), vv);
    rhs_volume = thread_rhs[0];
    for (int t = 1; t < nthreads; ++t) {
      const auto& tv = im.thread_values[static_cast<std::size_t>(t)];
      for (std::size_t k = 0; k < nnz; ++k) vv[k] += tv[k];
      rhs_volume += thread_rhs[static_cast<std::size_t>(t)];
    }
    double* av = A.valuePtr();
    std::copy(vv, vv + nnz, av);
    rhs = rhs_volume;

    // Nitsche terms on the interface (the seed paper's fluid weak form with P2 traces).
    const double g1 = params_.nitsche_penalty, g2 = params_.nitsche_symmetry, mu = params_.viscosity;
    for (const auto& ie : im.edges) {
      Eigen::Matrix<double, 6, 2> x;
      const auto nodes = mesh_.element_nodes6(ie.element);
      for (int k = 0; k < 6; ++k) x.row(k) = X_.row(nodes(k));
      Eigen::Matrix<double, 6, 2> vs = Eigen::Matrix<double, 6, 2>::Zero();
      for (int j = 0; j < 3; ++j)
        vs.row(kEdgeNodes[ie.edge][j]) = interface_velocity_.segment<2>(2 * ie.iface[static_cast<std::size_t>(j)]).transpose();
      Eigen::Matrix<double, 15, 15> local = Eigen::Matrix<double, 15, 15>::Zero();
      Eigen::Matrix<double, 15, 1> local_rhs = Eigen::Matrix<double, 15, 1>::Zero();
      Eigen::Matrix<double, 6, 2> x_pen = x;  // the penalty term's geometry
      if (params_.penalty_on_step_start)
        for (int k = 0; k < 6; ++k) x_pen.row(k) = X_n_.row(nodes(k));
      for (int g = 0; g < 4; ++g) {
        const auto p = edge_point(x, ie.edge, kGaussX[g]);
        const double w = kGaussW[g] * p.ds;
        const double w_pen = params_.penalty_on_step_start ? kGaussW[g] * edge_point(x_pen, ie.edge, kGaussX[g]).ds : w;
        const Eigen::Matrix<double, 6, 1> gn = p.G * p.normal;
        const Eigen::RowVector2d v = p.N.transpose() * vs;
        for (int i = 0; i < 6; ++i) {
          for (int j = 0; j < 6; ++j) {
            // (the default's arithmetic exactly as before the penalty_geometry option)
            const double vel = params_.penalty_on_step_start
                                   ? w_pen * g1 * p.N(i) * p.N(j) + w * (-mu * p.N(i) * gn(j) - g2 * mu * gn(i) * p.N(j))
                                   : w * (g1 * p.N(i) * p.N(j) - mu * p.N(i) * gn(j) - g2 * mu * gn(i) * p.N(j));
            for (int c = 0; c < 2; ++c) local(2 * i + c, 2 * j + c) += vel;
          }
          for (int j = 0; j < 3; ++j)
            for (int c = 0; c < 2; ++c) {
              local(2 * i + c, 12 + j) += w * p.N(i) * p.normal(c) * p.L(j);
              local(12 + j, 2 * i + c) += w * g2 * p.L(j) * p.normal(c) * p.N(i);
            }
          for (int c = 0; c < 2; ++c)
            local_rhs(2 * i + c) += params_.penalty_on_step_start ? (w_pen * g1 * p.N(i) - w * g2 * mu * gn(i)) * v(c)
                                                                  : w * (g1 * p.N(i) - g2 * mu * gn(i)) * v(c);
        }
        for (int j = 0; j < 3; ++j) local_rhs(12 + j) += w * g2 * p.L(j) * v.dot(p.normal.transpose());
      }
      const int* sc = &im.scatter[static_cast<std::size_t>(ie.element) * 225];
      for (int j = 0; j < 15; ++j)
        for (int i = 0; i < 15; ++i) av[sc[15 * j + i]] += local(i, j);
      const auto d = im.element_dofs(mesh_, ie.element);
      for (int i = 0; i < 15; ++i) rhs(d[static_cast<std::size_t>(i)]) += local_rhs(i);
    }

    detail::apply_constraints(A, rhs, constraints.on, constraints.value);
    report.assembly_seconds += seconds_since(t_assembly);

    im.last_rhs = rhs;
    Eigen::VectorXd U_new =
        im.lu->solve(A, rhs, retrial ? U_ : U_lin, report, fmt::format("fluid step at t = {:.6g}, iteration {}", time, iteration),
                       steady ? 0.0 : alpha0 / dt);

    double change = detail::relative_velocity_change(U_new, U_lin, n, [](int i, int c) { return 2 * i + c; });
    // Damped Newton: an update that grows the change is halved (iterations 3 on, so the first
    // Oseen/Stokes solve and the first Newton correction are always taken whole).
    if (params_.newton && iteration >= 3 && change > previous_change) {
      U_new = U_lin + 0.5 * (U_new - U_lin);
      change *= 0.5;
    }
    previous_change = change;
    report.change = change;
    report.iterations = iteration;
    U_ = U_new;
    U_lin = U_new;
    reaction_ = V * U_ - rhs_volume;
    if (report.change < params_.tolerance) break;
  }
  return report;
}

const Eigen::SparseMatrix<double>& TaylorHoodSolver::last_matrix() const { return impl_->matrix; }
const Eigen::VectorXd& TaylorHoodSolver::last_rhs() const { return impl_->last_rhs; }

void TaylorHoodSolver::accept() {
  U_nm1_ = U_n_;
  U_n_ = U_;
  X_nm1_ = X_n_;
  X_n_ = X_;
  dt_n_ = dt_trial_;
  ++accepted_;
  trial_solves_ = 0;
}

void TaylorHoodSolver::save_state(StateArchive& state, const std::string& prefix) {
  detail::save_flow_state(state, prefix, "p2p1",
                          {U_, U_n_, U_nm1_, reaction_, X_, X_n_, X_nm1_, dt_n_, dt_trial_, accepted_, trial_solves_,
                           interface_velocity_});
  impl_->lu->save_state(state, prefix + "lu.");
  impl_->lu->discard_factors();  // the next solve refactorises, as in a solver restored from this state
}

void TaylorHoodSolver::load_state(const StateArchive& state, const std::string& prefix) {
  detail::load_flow_state(state, prefix, "p2p1",
                          {U_, U_n_, U_nm1_, reaction_, X_, X_n_, X_nm1_, dt_n_, dt_trial_, accepted_, trial_solves_,
                           interface_velocity_});
  impl_->lu->load_state(state, prefix + "lu.");
}

Eigen::MatrixX2d TaylorHoodSolver::velocity() const {
  Eigen::MatrixX2d v(mesh_.node_count(), 2);
  for (int i = 0; i < mesh_.node_count(); ++i) v.row(i) << U_(2 * i), U_(2 * i + 1);
  return v;
}

Eigen::VectorXd TaylorHoodSolver::pressure() const {
  const int n = mesh_.node_count();
  Eigen::VectorXd p = Eigen::VectorXd::Zero(n);
  for (int i = 0; i < mesh_.vertices(); ++i) p(i) = U_(2 * n + i);
  for (int e = 0; e < mesh_.triangle_count(); ++e)
    for (int k = 0; k < 3; ++k)
      p(mesh_.edge_nodes(e, k)) = 0.5 * (p(mesh_.triangles(e, k)) + p(mesh_.triangles(e, (k + 1) % 3)));
  return p;
}

Eigen::Vector2d TaylorHoodSolver::force(const std::vector<std::string>& groups) const {
  Eigen::Vector2d f = Eigen::Vector2d::Zero();
  for (int node : mesh_.boundary_nodes(groups)) f -= reaction_.segment<2>(2 * node);
  return f;
}

Eigen::SparseMatrix<double> TaylorHoodSolver::interface_mass() const {
  const auto n = static_cast<Eigen::Index>(interface_nodes_.size());
  std::vector<Eigen::Triplet<double>> t;
  t.reserve(9 * impl_->edges.size());
  const Eigen::MatrixX2d& X = params_.penalty_on_step_start ? X_n_ : X_;
  for (const auto& ie : impl_->edges) {
    Eigen::Matrix<double, 6, 2> x;
    const auto nodes = mesh_.element_nodes6(ie.element);
    for (int k = 0; k < 6; ++k) x.row(k) = X.row(nodes(k));
    Eigen::Matrix3d m = Eigen::Matrix3d::Zero();
    for (int g = 0; g < 4; ++g) {
      const auto p = edge_point(x, ie.edge, kGaussX[g]);
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) m(i, j) += kGaussW[g] * p.ds * p.N(kEdgeNodes[ie.edge][i]) * p.N(kEdgeNodes[ie.edge][j]);
    }
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        t.emplace_back(ie.iface[static_cast<std::size_t>(i)], ie.iface[static_cast<std::size_t>(j)], m(i, j));
  }
  Eigen::SparseMatrix<double> out(n, n);
  out.setFromTriplets(t.begin(), t.end());
  return out;
}

Eigen::VectorXd TaylorHoodSolver::interface_velocity_integral() const {
  Eigen::VectorXd vf(2 * static_cast<Eigen::Index>(interface_nodes_.size()));
  for (std::size_t i = 0; i < interface_nodes_.size(); ++i)
    vf.segment<2>(2 * static_cast<Eigen::Index>(i)) = U_.segment<2>(2 * interface_nodes_[i]);
  return apply_nodal(interface_mass(), vf);  // f_v = M_f v_f, the penalty term's own operator
}

Eigen::VectorXd TaylorHoodSolver::interface_traction() const {
  const Eigen::Index ni = static_cast<Eigen::Index>(interface_nodes_.size());
  Eigen::VectorXd f(2 * ni);
  for (Eigen::Index i = 0; i < ni; ++i) f.segment<2>(2 * i) = reaction_.segment<2>(2 * interface_nodes_[static_cast<std::size_t>(i)]);
  return f + params_.nitsche_penalty * (interface_velocity_integral() - apply_nodal(interface_mass(), interface_velocity_));
}

bool TaylorHoodSolver::locate(const Eigen::Vector2d& point, int& element, Eigen::Vector3d& bary) const {
  return detail::locate(mesh_, X_, point, element, bary);
}

double TaylorHoodSolver::pressure_at(const Eigen::Vector2d& point) const {
  int e = 0;
  Eigen::Vector3d l;
  if (!locate(point, e, l)) return std::numeric_limits<double>::quiet_NaN();
  double p = 0;
  for (int k = 0; k < 3; ++k) p += l(k) * U_(2 * mesh_.node_count() + mesh_.triangles(e, k));
  return p;
}

Eigen::Vector2d TaylorHoodSolver::velocity_at(const Eigen::Vector2d& point) const {
  int e = 0;
  Eigen::Vector3d l;
  if (!locate(point, e, l)) return Eigen::Vector2d::Constant(std::numeric_limits<double>::quiet_NaN());
  Eigen::Matrix<double, 6, 1> N;
  Eigen::Matrix<double, 6, 2> dN;
  p2_shape(l(1), l(2), N, dN);
  const auto nodes = mesh_.element_nodes6(e);
  Eigen::Vector2d v = Eigen::Vector2d::Zero();
  for (int k = 0; k < 6; ++k) v += N(k) * U_.segment<2>(2 * nodes(k));
  return v;
}

}  // namespace fsi::fluid
