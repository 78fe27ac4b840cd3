#include "fsi/fluid/navier_stokes_solver.hpp"

#include <Eigen/LU>
#include <Eigen/SparseCore>
#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <map>
#include <set>

#include "fsi/common/solver_model.hpp"
#include "fsi/fluid/sparse_lu.hpp"
#include "flow_common.hpp"

#ifdef _OPENMP
#include <omp.h>
#endif

namespace fsi::fluid {
namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

// A boundary segment on the Nitsche interface with its parent triangle.
struct InterfaceSegment {
  int element;
  int local_a, local_b;  // local indices of the segment's nodes in the triangle
  int iface_a, iface_b;  // indices into interface_nodes
};

// div(mu grad u) per element (rows: triangles; constant in each), from the nodal gradients of
// the P1 velocity u (interleaved u, v, p) by lumped L2 projection:
// G_i = sum_e |e|/3 grad u_e / sum_e |e|/3. Degenerate elements get 0 (the assembly reports them).
Eigen::MatrixX2d element_viscous_term(const FluidMesh& mesh, const Eigen::MatrixX2d& X, const Eigen::VectorXd& u,
                                      double mu) {
  const int n = mesh.node_count(), ne = mesh.triangle_count();
  Eigen::MatrixXd grad = Eigen::MatrixXd::Zero(n, 4);  // du/dx, du/dy, dv/dx, dv/dy
  Eigen::VectorXd lumped = Eigen::VectorXd::Zero(n);
  std::vector<TriangleGeometry> geo(static_cast<std::size_t>(ne));
  for (int e = 0; e < ne; ++e) {
    Eigen::Matrix<double, 3, 2> x;
    for (int k = 0; k < 3; ++k) x.row(k) = X.row(mesh.triangles(e, k));
    const auto& g = geo[static_cast<std::size_t>(e)] = triangle_geometry(x);
    if (!(g.area > 0)) continue;
    Eigen::Matrix2d gu = Eigen::Matrix2d::Zero();  // row c: grad of component c
    for (int k = 0; k < 3; ++k)
      for (int c = 0; c < 2; ++c) gu.row(c) += u(3 * mesh.triangles(e, k) + c) * g.grad.row(k);
    for (int k = 0; k < 3; ++k) {
      const int node = mesh.triangles(e, k);
      lumped(node) += g.area / 3.0;
      grad.row(node) += g.area / 3.0 * Eigen::RowVector4d(gu(0, 0), gu(0, 1), gu(1, 0), gu(1, 1));
    }
  }
  for (int i = 0; i < n; ++i)
    if (lumped(i) > 0) grad.row(i) /= lumped(i);
  Eigen::MatrixX2d out = Eigen::MatrixX2d::Zero(ne, 2);
  for (int e = 0; e < ne; ++e) {
    const auto& g = geo[static_cast<std::size_t>(e)];
    if (!(g.area > 0)) continue;
    for (int k = 0; k < 3; ++k) {
      const int node = mesh.triangles(e, k);
      out(e, 0) += grad(node, 0) * g.grad(k, 0) + grad(node, 1) * g.grad(k, 1);
      out(e, 1) += grad(node, 2) * g.grad(k, 0) + grad(node, 3) * g.grad(k, 1);
    }
  }
  return mu * out;
}

}  // namespace

struct NavierStokesSolver::Impl {
  // Sparse pattern: column dof 3n+c holds rows 3m+r for m in adj(n) (sorted), r = 0..2.
  std::vector<std::vector<int>> adjacency;
  Eigen::SparseMatrix<double> matrix;       // system matrix (constraints applied)
  Eigen::SparseMatrix<double> volume;       // volume terms only (for reactions)
  std::vector<std::array<int, 9>> scatter;  // per element: 3*k offset of node a in adj(node b) -> index a*3+b
  std::unique_ptr<SparseLu> lu;
  std::vector<detail::DirichletCondition> dirichlet;
  std::vector<detail::SymmetryCondition> symmetry;
  std::vector<InterfaceSegment> segments;
  int pressure_node = -1;
  std::function<double(double)> pressure_value;
  VelocityFunction body_force;
  std::vector<std::vector<double>> thread_values;

};

NavierStokesSolver::NavierStokesSolver(FluidMesh mesh, FlowParameters params)
    : mesh_(std::move(mesh)), params_(params), impl_(std::make_unique<Impl>()) {
  if (mesh_.quadratic())
    throw std::invalid_argument("the P1/P1 fluid needs a mesh of 3-node triangles (this one has 6-node triangles: "
                                "use fluid.element: p2p1, or mesh with -order 1)");
  impl_->lu = std::make_unique<SparseLu>(params_);
  const int n = mesh_.node_count();
  auto& adj = impl_->adjacency;
  adj.assign(static_cast<std::size_t>(n), {});
  for (int e = 0; e < mesh_.triangle_count(); ++e)
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) adj[static_cast<std::size_t>(mesh_.triangles(e, j))].push_back(mesh_.triangles(e, i));
  std::size_t nnz = 0;
  for (auto& list : adj) {
    std::sort(list.begin(), list.end());
    list.erase(std::unique(list.begin(), list.end()), list.end());
    nnz += 9 * list.size();
  }
  // Build the CSC structure directly.
  auto& A = impl_->matrix;
  A.resize(3 * n, 3 * n);
  A.resizeNonZeros(static_cast<Eigen::Index>(nnz));
  int* outer = A.outerIndexPtr();
  int* inner = A.innerIndexPtr();
  int pos = 0;
  for (int b = 0; b < n; ++b)
    for (int c = 0; c < 3; ++c) {
      outer[3 * b + c] = pos;
      for (int a : adj[static_cast<std::size_t>(b)])
        for (int r = 0; r < 3; ++r) inner[pos++] = 3 * a + r;
    }
  outer[3 * n] = pos;
  A.valuePtr()[0] = 0;
  std::fill(A.valuePtr(), A.valuePtr() + nnz, 0.0);
  impl_->volume = A;
  impl_->scatter.resize(static_cast<std::size_t>(mesh_.triangle_count()));
  for (int e = 0; e < mesh_.triangle_count(); ++e)
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) {
        const auto& list = adj[static_cast<std::size_t>(mesh_.triangles(e, j))];
        const auto it = std::lower_bound(list.begin(), list.end(), mesh_.triangles(e, i));
        impl_->scatter[static_cast<std::size_t>(e)][3 * i + j] = 3 * static_cast<int>(it - list.begin());
      }
  U_ = U_n_ = U_nm1_ = reaction_ = Eigen::VectorXd::Zero(3 * n);
  X_ = X_n_ = X_nm1_ = mesh_.nodes;
  interface_segments_.resize(0, 2);
}

NavierStokesSolver::~NavierStokesSolver() = default;
NavierStokesSolver::NavierStokesSolver(NavierStokesSolver&&) noexcept = default;
NavierStokesSolver& NavierStokesSolver::operator=(NavierStokesSolver&&) noexcept = default;

void NavierStokesSolver::add_dirichlet(const std::string& group, VelocityFunction velocity) {
  impl_->dirichlet.push_back({mesh_.boundary_nodes({group}), std::move(velocity)});
}

void NavierStokesSolver::add_symmetry(const std::string& group) {
  impl_->symmetry.push_back({mesh_.boundary_nodes({group}), detail::symmetry_component(mesh_, group)});
}

void NavierStokesSolver::set_interface(const std::vector<std::string>& groups) {
  interface_nodes_ = mesh_.boundary_nodes(groups);
  std::map<int, int> local;
  for (std::size_t i = 0; i < interface_nodes_.size(); ++i) local[interface_nodes_[i]] = static_cast<int>(i);
  std::map<std::pair<int, int>, int> edge_owner;
  for (int e = 0; e < mesh_.triangle_count(); ++e)
    for (int k = 0; k < 3; ++k) {
      const int a = mesh_.triangles(e, k), b = mesh_.triangles(e, (k + 1) % 3);
      edge_owner[{std::min(a, b), std::max(a, b)}] = e;
    }
  impl_->segments.clear();
  std::vector<std::array<int, 2>> segs;
  for (const auto& name : groups) {
    const auto& seg = mesh_.boundary(name);
    for (Eigen::Index s = 0; s < seg.rows(); ++s) {
      const int a = seg(s, 0), b = seg(s, 1);
      const auto it = edge_owner.find({std::min(a, b), std::max(a, b)});
      if (it == edge_owner.end())
        throw std::runtime_error(fmt::format("interface group '{}': segment ({}, {}) is not a triangle edge", name, a, b));
      InterfaceSegment is{};
      is.element = it->second;
      for (int k = 0; k < 3; ++k) {
        if (mesh_.triangles(is.element, k) == a) is.local_a = k;
        if (mesh_.triangles(is.element, k) == b) is.local_b = k;
      }
      is.iface_a = local.at(a);
      is.iface_b = local.at(b);
      impl_->segments.push_back(is);
      segs.push_back({is.iface_a, is.iface_b});
    }
  }
  interface_segments_.resize(static_cast<Eigen::Index>(segs.size()), 2);
  for (std::size_t s = 0; s < segs.size(); ++s) interface_segments_.row(static_cast<Eigen::Index>(s)) << segs[s][0], segs[s][1];
  interface_velocity_ = Eigen::VectorXd::Zero(2 * static_cast<Eigen::Index>(interface_nodes_.size()));
}

void NavierStokesSolver::set_pressure_reference(const Eigen::Vector2d& point, std::function<double(double)> value) {
  Eigen::Index best = 0;
  (mesh_.nodes.rowwise() - point.transpose()).rowwise().squaredNorm().minCoeff(&best);
  impl_->pressure_node = static_cast<int>(best);
  impl_->pressure_value = std::move(value);
}

void NavierStokesSolver::set_body_force(VelocityFunction force) { impl_->body_force = std::move(force); }

void NavierStokesSolver::set_initial_velocity(const Eigen::MatrixX2d& velocity) {
  for (int i = 0; i < mesh_.node_count(); ++i) {
    U_n_(3 * i) = U_nm1_(3 * i) = U_(3 * i) = velocity(i, 0);
    U_n_(3 * i + 1) = U_nm1_(3 * i + 1) = U_(3 * i + 1) = velocity(i, 1);
  }
}

StepReport NavierStokesSolver::solve(double time, double dt, const Eigen::MatrixX2d& positions,
                                     const Eigen::VectorXd& interface_velocity) {
  StepReport report;
  const int n = mesh_.node_count();
  const int ndof = 3 * n;
  if (positions.rows() != n) throw std::invalid_argument("NavierStokesSolver::solve: positions has the wrong size");
  X_ = positions;
  dt_trial_ = dt;
  if (interface_velocity.size() == 0) interface_velocity_.setZero();
  else if (interface_velocity.size() != 2 * static_cast<Eigen::Index>(interface_nodes_.size()))
    throw std::invalid_argument(fmt::format("interface velocity has {} entries, expected {}", interface_velocity.size(),
                                            2 * interface_nodes_.size()));
  else interface_velocity_ = interface_velocity;

  // Time discretisation: du/dt ~ (alpha0 u + alpha1 u_n + alpha2 u_{n-1}) / dt.
  const bool steady = params_.scheme == TimeScheme::Steady;
  const auto [alpha0, alpha1, alpha2, extrap] = detail::bdf_coefficients(params_.scheme, accepted_, dt, dt_n_);
  // Mesh velocity (BDF-consistent with the time derivative of the velocity).
  Eigen::MatrixX2d mesh_velocity = Eigen::MatrixX2d::Zero(n, 2);
  if (!steady) mesh_velocity = (alpha0 * X_ + alpha1 * X_n_ + alpha2 * X_nm1_) / dt;

  Eigen::VectorXd U_adv = steady ? U_n_ : Eigen::VectorXd((1 + extrap) * U_n_ - extrap * U_nm1_);
  // A later coupling iteration of the step starts its linear solve from the last iterate's
  // solution (closer than the extrapolation; the system solved is the same).
  const bool retrial = trial_solves_ > 0 && U_.size() == U_adv.size();
  if (params_.relinearise && trial_solves_ > 0) U_adv = U_;  // a coupling iteration: about the last iterate
  ++trial_solves_;
  Eigen::VectorXd history = Eigen::VectorXd::Zero(ndof);
  if (!steady) history = (alpha1 * U_n_ + alpha2 * U_nm1_) / dt;

  // Constraints at t_{n+1} on the current positions.
  const auto constraints = detail::strong_constraints(ndof, impl_->dirichlet, impl_->symmetry, X_, time,
                                                      [](int i, int c) { return 3 * i + c; },
                                                      impl_->pressure_node >= 0 ? 3 * impl_->pressure_node + 2 : -1, impl_->pressure_value ? impl_->pressure_value(time) : 0.0);
  Eigen::MatrixX2d body = Eigen::MatrixX2d::Zero(n, 2);
  if (impl_->body_force)
    for (int i = 0; i < n; ++i) body.row(i) = impl_->body_force(X_.row(i).transpose(), time).transpose();

  auto& A = impl_->matrix;
  auto& V = impl_->volume;
  const std::size_t nnz = static_cast<std::size_t>(A.nonZeros());
  const int* outer = A.outerIndexPtr();
  const int nthreads = std::max(1, params_.threads);
  impl_->thread_values.resize(static_cast<std::size_t>(nthreads));
  Eigen::VectorXd rhs(ndof), rhs_volume(ndof);

  // Reconstructed viscous residual (div(mu grad u*) per element), see element_viscous_term.
  const bool reconstruct = params_.stabilisation.viscous_residual && (params_.stabilisation.supg || params_.stabilisation.pspg);
  Eigen::MatrixX2d element_viscous;

  for (int iteration = 1; iteration <= std::max(1, params_.max_iterations); ++iteration) {
    const auto t_assembly = Clock::now();
    if (reconstruct) element_viscous = element_viscous_term(mesh_, X_, U_adv, params_.viscosity);
    std::vector<Eigen::VectorXd> thread_rhs(static_cast<std::size_t>(nthreads), Eigen::VectorXd::Zero(ndof));
    int bad_element = -1;
    double bad_area = 0;
#pragma omp parallel num_threads(nthreads)
    {
#ifdef _OPENMP
      const int tid = omp_get_thread_num();
#else
      const int tid = 0;
#endif
      auto& values = impl_->thread_values[static_cast<std::size_t>(tid)];
      values.assign(nnz, 0.0);
      auto& b = thread_rhs[static_cast<std::size_t>(tid)];
      ElementInput in;
      ElementOutput out;
      in.density = params_.density;
      in.viscosity = params_.viscosity;
      in.alpha0_dt = steady ? 0.0 : alpha0 / dt;
      in.dt = steady ? 0.0 : dt;
      in.newton = params_.newton;
#pragma omp for schedule(static)
      for (int e = 0; e < mesh_.triangle_count(); ++e) {
        for (int k = 0; k < 3; ++k) {
          const int node = mesh_.triangles(e, k);
          in.x.row(k) = X_.row(node);
          in.velocity(k, 0) = U_adv(3 * node);
          in.velocity(k, 1) = U_adv(3 * node + 1);
          in.advection(k, 0) = U_adv(3 * node) - mesh_velocity(node, 0);
          in.advection(k, 1) = U_adv(3 * node + 1) - mesh_velocity(node, 1);
          in.history(k, 0) = history(3 * node);
          in.history(k, 1) = history(3 * node + 1);
          in.force.row(k) = body.row(node);
        }
        if (reconstruct) in.viscous = element_viscous.row(e);
        const double area = triangle_geometry(in.x).area;
        if (!(area > 0)) {
#pragma omp critical
          {
            bad_element = e;
            bad_area = area;
          }
          continue;
        }
        assemble_element(in, params_.stabilisation, out);
        for (int j = 0; j < 3; ++j) {
          const int node_b = mesh_.triangles(e, j);
          for (int i = 0; i < 3; ++i) {
            const int base_off = impl_->scatter[static_cast<std::size_t>(e)][3 * i + j];
            for (int c = 0; c < 3; ++c) {
              const int col_start = outer[3 * node_b + c] + base_off;
              for (int r = 0; r < 3; ++r) values[static_cast<std::size_t>(col_start + r)] += out.matrix(3 * i + r, 3 * j + c);
            }
          }
          for (int r = 0; r < 3; ++r) b(3 * node_b + r) += out.rhs(3 * j + r);
        }
      }
    }
    if (bad_element >= 0) {
      const Eigen::RowVector2d centre = (X_.row(mesh_.triangles(bad_element, 0)) + X_.row(mesh_.triangles(bad_element, 1)) +
                                         X_.row(mesh_.triangles(bad_element, 2))) / 3.0;
      throw SolverError(fmt::format("fluid step at t = {:.6g}: element {} near ({:.5g}, {:.5g}) is inverted or degenerate "
                                    "(area {:.3g}); the mesh motion tangled the mesh",
                                    time, bad_element, centre(0), centre(1), bad_area));
    }
    double* vv = V.valuePtr();
    std::copy(impl_->thread_values[0].begin(), impl_->thread_values[0].end(), vv);
    rhs_volume = thread_rhs[0];
    for (int t = 1; t < nthreads; ++t) {
      const auto& tv = impl_->thread_values[static_cast<std::size_t>(t)];
      for (std::size_t k = 0; k < nnz; ++k) vv[k] += tv[k];
      rhs_volume += thread_rhs[static_cast<std::size_t>(t)];
    }
    double* av = A.valuePtr();
    std::copy(vv, vv + nnz, av);
    rhs = rhs_volume;

    // Nitsche terms on the interface (paper's fluid weak form, pseudo-stress sigma = mu grad v - p I).
    const double g1 = params_.nitsche_penalty, g2 = params_.nitsche_symmetry, mu = params_.viscosity;
    for (const auto& s : impl_->segments) {
      Eigen::Matrix<double, 3, 2> x;
      for (int k = 0; k < 3; ++k) x.row(k) = X_.row(mesh_.triangles(s.element, k));
      const auto geo = triangle_geometry(x);
      const Eigen::Vector2d xa = x.row(s.local_a).transpose(), xb = x.row(s.local_b).transpose();
      const double length = (xb - xa).norm();
      Eigen::Vector2d normal((xb - xa).y(), -(xb - xa).x());
      normal /= length;
      const int third = 3 - s.local_a - s.local_b;
      if (normal.dot(x.row(third).transpose() - xa) > 0) normal = -normal;  // outward of the fluid
      Eigen::Matrix3d mass = Eigen::Matrix3d::Zero();  // int_seg N_i N_j
      Eigen::Vector3d integral = Eigen::Vector3d::Zero();
      mass(s.local_a, s.local_a) = mass(s.local_b, s.local_b) = length / 3.0;
      mass(s.local_a, s.local_b) = mass(s.local_b, s.local_a) = length / 6.0;
      integral(s.local_a) = integral(s.local_b) = length / 2.0;
      // The penalty term's mass: on this interface, or on the last accepted step's.
      Eigen::Matrix3d penalty_mass = mass;
      if (params_.penalty_on_step_start) {
        const double ln = (X_n_.row(mesh_.triangles(s.element, s.local_b)) - X_n_.row(mesh_.triangles(s.element, s.local_a))).norm();
        penalty_mass = mass * (ln / length);
      }
      const Eigen::Vector3d gn = geo.grad * normal;  // grad N_i . n
      Eigen::Matrix<double, 3, 2> vs = Eigen::Matrix<double, 3, 2>::Zero();
      vs.row(s.local_a) = interface_velocity_.segment<2>(2 * s.iface_a).transpose();
      vs.row(s.local_b) = interface_velocity_.segment<2>(2 * s.iface_b).transpose();
      const Eigen::Matrix<double, 3, 2> mass_vs = mass * vs, penalty_vs = penalty_mass * vs;
      const Eigen::RowVector2d int_vs = integral.transpose() * vs;
      Eigen::Matrix<double, 9, 9> local = Eigen::Matrix<double, 9, 9>::Zero();
      Eigen::Matrix<double, 9, 1> local_rhs = Eigen::Matrix<double, 9, 1>::Zero();
      for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) {
          const double vel = g1 * penalty_mass(i, j) - mu * integral(i) * gn(j) - g2 * mu * gn(i) * integral(j);
          for (int c = 0; c < 2; ++c) {
            local(3 * i + c, 3 * j + c) += vel;
            local(3 * i + c, 3 * j + 2) += normal(c) * mass(i, j);
            local(3 * i + 2, 3 * j + c) += g2 * normal(c) * mass(i, j);
          }
        }
        for (int c = 0; c < 2; ++c) local_rhs(3 * i + c) = g1 * penalty_vs(i, c) - g2 * mu * gn(i) * int_vs(c);
        local_rhs(3 * i + 2) = g2 * mass_vs.row(i).dot(normal.transpose());
      }
      for (int j = 0; j < 3; ++j) {
        const int node_b = mesh_.triangles(s.element, j);
        for (int i = 0; i < 3; ++i) {
          const int base_off = impl_->scatter[static_cast<std::size_t>(s.element)][3 * i + j];
          for (int c = 0; c < 3; ++c)
            for (int r = 0; r < 3; ++r) av[outer[3 * node_b + c] + base_off + r] += local(3 * i + r, 3 * j + c);
        }
        for (int r = 0; r < 3; ++r) rhs(3 * node_b + r) += local_rhs(3 * j + r);
      }
    }

    // Strong constraints: identity rows.
    detail::apply_constraints(A, rhs, constraints.on, constraints.value);
    report.assembly_seconds += seconds_since(t_assembly);

    const Eigen::VectorXd U_new =
        impl_->lu->solve(A, rhs, retrial ? U_ : U_adv, report, fmt::format("fluid step at t = {:.6g}, iteration {}", time, iteration),
                       steady ? 0.0 : alpha0 / dt);

    report.change = detail::relative_velocity_change(U_new, U_adv, n, [](int i, int c) { return 3 * i + c; });
    report.iterations = iteration;
    U_ = U_new;
    U_adv = U_new;
    reaction_ = V * U_ - rhs_volume;
    if (report.change < params_.tolerance) break;
  }
  return report;
}

void NavierStokesSolver::accept() {
  U_nm1_ = U_n_;
  U_n_ = U_;
  X_nm1_ = X_n_;
  X_n_ = X_;
  dt_n_ = dt_trial_;
  ++accepted_;
  trial_solves_ = 0;
}

void NavierStokesSolver::save_state(StateArchive& state, const std::string& prefix) {
  detail::save_flow_state(state, prefix, "p1p1",
                          {U_, U_n_, U_nm1_, reaction_, X_, X_n_, X_nm1_, dt_n_, dt_trial_, accepted_, trial_solves_,
                           interface_velocity_});
  impl_->lu->save_state(state, prefix + "lu.");
  impl_->lu->discard_factors();  // the next solve refactorises, as in a solver restored from this state
}

void NavierStokesSolver::load_state(const StateArchive& state, const std::string& prefix) {
  detail::load_flow_state(state, prefix, "p1p1",
                          {U_, U_n_, U_nm1_, reaction_, X_, X_n_, X_nm1_, dt_n_, dt_trial_, accepted_, trial_solves_,
                           interface_velocity_});
  impl_->lu->load_state(state, prefix + "lu.");
}

Eigen::MatrixX2d NavierStokesSolver::velocity() const {
  Eigen::MatrixX2d v(mesh_.node_count(), 2);
  for (int i = 0; i < mesh_.node_count(); ++i) v.row(i) << U_(3 * i), U_(3 * i + 1);
  return v;
}

Eigen::VectorXd NavierStokesSolver::pressure() const {
  Eigen::VectorXd p(mesh_.node_count());
  for (int i = 0; i < mesh_.node_count(); ++i) p(i) = U_(3 * i + 2);
  return p;
}

Eigen::Vector2d NavierStokesSolver::force(const std::vector<std::string>& groups) const {
  Eigen::Vector2d f = Eigen::Vector2d::Zero();
  for (int node : mesh_.boundary_nodes(groups)) f -= reaction_.segment<2>(3 * node);
  return f;
}

Eigen::VectorXd NavierStokesSolver::interface_velocity_integral() const {
  Eigen::VectorXd vf(2 * static_cast<Eigen::Index>(interface_nodes_.size()));
  for (std::size_t i = 0; i < interface_nodes_.size(); ++i)
    vf.segment<2>(2 * static_cast<Eigen::Index>(i)) = U_.segment<2>(3 * interface_nodes_[i]);
  return apply_nodal(interface_mass(), vf);  // f_v = M_f v_f, the penalty term's own operator
}

Eigen::SparseMatrix<double> NavierStokesSolver::interface_mass() const {
  const auto n = static_cast<Eigen::Index>(interface_nodes_.size());
  std::vector<Eigen::Triplet<double>> t;
  t.reserve(4 * impl_->segments.size());
  const Eigen::MatrixX2d& X = params_.penalty_on_step_start ? X_n_ : X_;
  for (const auto& s : impl_->segments) {
    const int na = interface_nodes_[static_cast<std::size_t>(s.iface_a)], nb = interface_nodes_[static_cast<std::size_t>(s.iface_b)];
    const double length = (X.row(nb) - X.row(na)).norm();
    t.emplace_back(s.iface_a, s.iface_a, length / 3.0);
    t.emplace_back(s.iface_b, s.iface_b, length / 3.0);
    t.emplace_back(s.iface_a, s.iface_b, length / 6.0);
    t.emplace_back(s.iface_b, s.iface_a, length / 6.0);
  }
  Eigen::SparseMatrix<double> m(n, n);
  m.setFromTriplets(t.begin(), t.end());
  return m;
}

Eigen::VectorXd NavierStokesSolver::interface_traction() const {
  const Eigen::Index ni = static_cast<Eigen::Index>(interface_nodes_.size());
  Eigen::VectorXd f(2 * ni);
  for (Eigen::Index i = 0; i < ni; ++i) f.segment<2>(2 * i) = reaction_.segment<2>(3 * interface_nodes_[static_cast<std::size_t>(i)]);
  // + gamma_N1 int N^T (v_f - v_s) = gamma_N1 (f_v - M_f v_s)
  return f + params_.nitsche_penalty * (interface_velocity_integral() - apply_nodal(interface_mass(), interface_velocity_));
}

bool NavierStokesSolver::locate(const Eigen::Vector2d& point, int& element, Eigen::Vector3d& bary) const {
  return detail::locate(mesh_, X_, point, element, bary);
}

double NavierStokesSolver::pressure_at(const Eigen::Vector2d& point) const {
  int e = 0;
  Eigen::Vector3d l;
  if (!locate(point, e, l)) return std::numeric_limits<double>::quiet_NaN();
  double p = 0;
  for (int k = 0; k < 3; ++k) p += l(k) * U_(3 * mesh_.triangles(e, k) + 2);
  return p;
}

Eigen::Vector2d NavierStokesSolver::velocity_at(const Eigen::Vector2d& point) const {
  int e = 0;
  Eigen::Vector3d l;
  if (!locate(point, e, l)) return Eigen::Vector2d::Constant(std::numeric_limits<double>::quiet_NaN());
  Eigen::Vector2d v = Eigen::Vector2d::Zero();
  for (int k = 0; k < 3; ++k) v += l(k) * U_.segment<2>(3 * mesh_.triangles(e, k));
  return v;
}

}  // namespace fsi::fluid
