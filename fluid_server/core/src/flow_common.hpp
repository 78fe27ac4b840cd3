#pragma once
// Pieces both fluid solvers (P1/P1 and Taylor-Hood P2/P1) share: the variable-step BDF
// coefficients, the axis of a symmetry boundary, the point location on the vertex triangles,
// the strong constraints as identity rows, the relative velocity change. Private to fsi_fluid.
#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "fsi/common/state.hpp"
#include "fsi/fluid/flow_solver.hpp"

namespace fsi::fluid::detail {

struct DirichletCondition {
  std::vector<int> nodes;
  VelocityFunction velocity;
};

struct SymmetryCondition {
  std::vector<int> nodes;
  int component;  // constrained velocity component (normal to the boundary)
};

// The strong constraints at `time` on the positions X: which unknowns, and their values.
// dof(node, c) is the velocity unknown; pressure_dof < 0 means no pressure reference.
struct StrongConstraints {
  std::vector<char> on;
  Eigen::VectorXd value;
};

template <class VelocityDof>
StrongConstraints strong_constraints(int ndof, const std::vector<DirichletCondition>& dirichlet,
                                     const std::vector<SymmetryCondition>& symmetry, const Eigen::MatrixX2d& X,
                                     double time, VelocityDof dof, int pressure_dof, double pressure_value) {
  StrongConstraints k{std::vector<char>(static_cast<std::size_t>(ndof), 0), Eigen::VectorXd::Zero(ndof)};
  for (const auto& sym : symmetry)
    for (int node : sym.nodes) k.on[static_cast<std::size_t>(dof(node, sym.component))] = 1;
  for (const auto& dc : dirichlet)
    for (int node : dc.nodes) {
      const Eigen::Vector2d v = dc.velocity(X.row(node).transpose(), time);
      for (int c = 0; c < 2; ++c) {
        k.on[static_cast<std::size_t>(dof(node, c))] = 1;
        k.value(dof(node, c)) = v(c);
      }
    }
  if (pressure_dof >= 0) {
    k.on[static_cast<std::size_t>(pressure_dof)] = 1;
    k.value(pressure_dof) = pressure_value;
  }
  return k;
}

// du/dt ~ (alpha0 u + alpha1 u_n + alpha2 u_{n-1}) / dt; the semi-implicit advection velocity
// u* = (1 + extrap) u_n - extrap u_{n-1}. BDF2 with variable steps (first step BDF1).
struct BdfCoefficients {
  double alpha0 = 0, alpha1 = 0, alpha2 = 0, extrap = 0;
};

inline BdfCoefficients bdf_coefficients(TimeScheme scheme, int accepted_steps, double dt, double dt_previous) {
  BdfCoefficients c;
  if (scheme == TimeScheme::Steady) return c;
  if (scheme == TimeScheme::BDF2 && accepted_steps >= 1 && dt_previous > 0) {
    const double w = dt / dt_previous;
    c.alpha0 = (1 + 2 * w) / (1 + w);
    c.alpha1 = -(1 + w);
    c.alpha2 = w * w / (1 + w);
    c.extrap = w;
  } else {
    c.alpha0 = 1;
    c.alpha1 = -1;
  }
  return c;
}

// The velocity component a symmetry group constrains: 1 (v) on y = const, 0 (u) on x = const.
inline int symmetry_component(const FluidMesh& mesh, const std::string& group) {
  const auto& seg = mesh.boundary(group);
  Eigen::Vector2d span = Eigen::Vector2d::Zero();
  for (Eigen::Index e = 0; e < seg.rows(); ++e)
    span += (mesh.nodes.row(seg(e, 1)) - mesh.nodes.row(seg(e, 0))).transpose().cwiseAbs();
  const double tol = 1e-8 * span.norm();
  if (span.y() <= tol) return 1;
  if (span.x() <= tol) return 0;
  throw std::runtime_error("symmetry boundary '" + group + "' is not axis-aligned (only x = const or y = const)");
}

// The vertex triangle of `mesh` (at positions X) holding `point`, with barycentric
// coordinates; false when the point is outside (by more than round-off).
inline bool locate(const FluidMesh& mesh, const Eigen::MatrixX2d& X, const Eigen::Vector2d& point, int& element,
                   Eigen::Vector3d& bary) {
  double best = -std::numeric_limits<double>::infinity();
  for (int e = 0; e < mesh.triangle_count(); ++e) {
    const Eigen::Vector2d a = X.row(mesh.triangles(e, 0)), b = X.row(mesh.triangles(e, 1)), c = X.row(mesh.triangles(e, 2));
    Eigen::Matrix2d J;
    J << b - a, c - a;
    const Eigen::Vector2d s = J.inverse() * (point - a);
    const Eigen::Vector3d l(1 - s(0) - s(1), s(0), s(1));
    const double m = l.minCoeff();
    if (m > best) {
      best = m;
      element = e;
      bary = l;
      if (m >= 0) return true;
    }
  }
  return best > -1e-9;
}

// Strong constraints: the constrained rows of A become identity rows, their rhs the value.
inline void apply_constraints(Eigen::SparseMatrix<double>& A, Eigen::VectorXd& rhs, const std::vector<char>& constrained,
                              const Eigen::VectorXd& value) {
  const int* outer = A.outerIndexPtr();
  const int* inner = A.innerIndexPtr();
  double* av = A.valuePtr();
  for (Eigen::Index col = 0; col < A.cols(); ++col)
    for (int k = outer[col]; k < outer[col + 1]; ++k)
      if (constrained[static_cast<std::size_t>(inner[k])]) av[k] = inner[k] == col ? 1.0 : 0.0;
  for (Eigen::Index d = 0; d < rhs.size(); ++d)
    if (constrained[static_cast<std::size_t>(d)]) rhs(d) = value(d);
}

// ||u_new - u_old|| / ||u_new|| over the velocity unknowns (index(i, c) for node i, component c).
template <class Index>
double relative_velocity_change(const Eigen::VectorXd& u_new, const Eigen::VectorXd& u_old, int nodes, Index index) {
  double diff = 0, norm = 0;
  for (int i = 0; i < nodes; ++i)
    for (int c = 0; c < 2; ++c) {
      const int k = index(i, c);
      diff += std::pow(u_new(k) - u_old(k), 2);
      norm += std::pow(u_new(k), 2);
    }
  return std::sqrt(diff / std::max(norm, 1e-300));
}

// The time-stepping state both solvers carry from one step to the next (checkpoints): the
// solution of the last solve and the BDF history, the mesh positions of the last solve and
// the two accepted levels (the BDF mesh velocity), the step sizes and counts (BDF1 vs BDF2,
// relinearisation), the interface velocity of the last solve, the reactions (forces).
struct FlowState {
  Eigen::VectorXd &U, &U_n, &U_nm1, &reaction;
  Eigen::MatrixX2d &X, &X_n, &X_nm1;
  double &dt_n, &dt_trial;
  int &accepted, &trial_solves;
  Eigen::VectorXd& interface_velocity;
};

inline Eigen::VectorXd flatten(const Eigen::MatrixX2d& m) { return Eigen::Map<const Eigen::VectorXd>(m.data(), m.size()); }

inline Eigen::MatrixX2d unflatten(const Eigen::VectorXd& v) {
  return Eigen::Map<const Eigen::MatrixX2d>(v.data(), v.size() / 2, 2);
}

// Entries under `prefix`: element (text), u, u_n, u_nm1, reaction (every unknown), x, x_n,
// x_nm1 (every node, column-major: all x then all y), dt_n, dt_trial, accepted_steps,
// trial_solves, interface_velocity (2 per interface node).
inline void save_flow_state(StateArchive& state, const std::string& prefix, const std::string& element,
                            const FlowState& f) {
  state.put(prefix + "element", element);
  state.put(prefix + "u", f.U);
  state.put(prefix + "u_n", f.U_n);
  state.put(prefix + "u_nm1", f.U_nm1);
  state.put(prefix + "reaction", f.reaction);
  state.put(prefix + "x", flatten(f.X));
  state.put(prefix + "x_n", flatten(f.X_n));
  state.put(prefix + "x_nm1", flatten(f.X_nm1));
  state.put(prefix + "dt_n", f.dt_n);
  state.put(prefix + "dt_trial", f.dt_trial);
  state.put(prefix + "accepted_steps", static_cast<std::int64_t>(f.accepted));
  state.put(prefix + "trial_solves", static_cast<std::int64_t>(f.trial_solves));
  state.put(prefix + "interface_velocity", f.interface_velocity);
}

// Reads every entry before changing anything: a state that does not fit (another element,
// mesh or interface) throws fsi::StateError naming the entry and leaves the solver as it was.
inline void load_flow_state(const StateArchive& state, const std::string& prefix, const std::string& element,
                            const FlowState& f) {
  const std::string saved = state.text(prefix + "element");
  if (saved != element)
    throw StateError(fmt::format("entry '{}element' is '{}', this configuration uses fluid.element {}", prefix, saved,
                                 element));
  const Eigen::Index ndof = f.U.size(), npos = f.X.size();
  Eigen::VectorXd U = state.vector(prefix + "u", ndof), U_n = state.vector(prefix + "u_n", ndof),
                  U_nm1 = state.vector(prefix + "u_nm1", ndof), reaction = state.vector(prefix + "reaction", ndof);
  const Eigen::VectorXd X = state.vector(prefix + "x", npos), X_n = state.vector(prefix + "x_n", npos),
                        X_nm1 = state.vector(prefix + "x_nm1", npos);
  Eigen::VectorXd iface = state.vector(prefix + "interface_velocity", f.interface_velocity.size());
  const double dt_n = state.real(prefix + "dt_n"), dt_trial = state.real(prefix + "dt_trial");
  const auto accepted = state.integer(prefix + "accepted_steps"), trial = state.integer(prefix + "trial_solves");
  if (accepted < 0 || trial < 0)
    throw StateError(fmt::format("entries '{}accepted_steps' / '{}trial_solves' are negative", prefix, prefix));
  f.U = std::move(U);
  f.U_n = std::move(U_n);
  f.U_nm1 = std::move(U_nm1);
  f.reaction = std::move(reaction);
  f.X = unflatten(X);
  f.X_n = unflatten(X_n);
  f.X_nm1 = unflatten(X_nm1);
  f.interface_velocity = std::move(iface);
  f.dt_n = dt_n;
  f.dt_trial = dt_trial;
  f.accepted = static_cast<int>(accepted);
  f.trial_solves = static_cast<int>(trial);
}

}  // namespace fsi::fluid::detail
