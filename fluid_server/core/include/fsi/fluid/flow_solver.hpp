#pragma once
// What both fluid discretisations share: the parameters of a flow solve, the report of one
// solve, and the interface NavierStokesFluid drives (FlowSolver), implemented by
//   NavierStokesSolver  - equal-order P1/P1 with SUPG/PSPG/LSIC (the seed paper's element)
//   TaylorHoodSolver    - isoparametric Taylor-Hood P2/P1 (inf-sup stable; optional SUPG, grad-div)
// Pure numerics: Eigen in, Eigen out; no configuration files, sockets or output.
#include <Eigen/Core>
#include <Eigen/SparseCore>

#include <functional>
#include <string>
#include <vector>

#include "fsi/common/state.hpp"
#include "fsi/fluid/mesh.hpp"

namespace fsi::fluid {

using VelocityFunction = std::function<Eigen::Vector2d(const Eigen::Vector2d& x, double t)>;

enum class TimeScheme { Steady, BDF1, BDF2 };

struct StabilisationParameters {
  bool supg = true;
  bool pspg = true;               // P1/P1 only (Taylor-Hood is inf-sup stable)
  double lsic_scale = 1.0;        // P1/P1: multiplies tau_C = h^2 / (8 tau_M); 0 switches LSIC off
  double grad_div = 0.0;          // P2/P1: gamma in gamma (div w, div u) (units of a dynamic viscosity)
  double viscous_constant = 3.0;  // c in tau_M^-2 = (2/dt)^2 + (2|a|/h)^2 + (c 4 nu/h^2)^2
  bool transient_tau = true;      // include the (2/dt)^2 term
  bool viscous_residual = false;  // P1/P1: include the reconstructed div(mu grad u*) in r_M
};

// Fill-reducing ordering of the sparse LU (UMFPACK); Auto tries both on the first matrix and
// keeps the one whose factorisation needs fewer flops.
enum class Ordering { Amd, Metis, Auto };
// UMFPACK's strategy: Symmetric (AMD/METIS on A + A^T, diagonal pivots preferred) suits both
// elements' saddle-point matrices (measured: 20 % faster factorisations, 30 % faster solves
// than Auto on Taylor-Hood); Auto lets UMFPACK decide from the pattern.
enum class LuStrategy { Auto, Symmetric, Unsymmetric };

struct FlowParameters {
  double density = 1.0;
  double viscosity = 1e-3;  // dynamic
  TimeScheme scheme = TimeScheme::BDF2;
  int max_iterations = 1;   // nonlinear solves per step
  double tolerance = 1e-10; // stop when the relative velocity change falls below
  // Newton: the exact Jacobian of the Galerkin convection term ((du . grad) u_k added to the
  // Oseen operator); false: Picard (Oseen) iterations. The first solve of a time step always
  // advects with the extrapolated velocity, so max_iterations = 1 is the semi-implicit scheme.
  bool newton = false;
  // A repeated solve of the same time level (a coupling iteration) linearises about the last
  // solve's velocity instead of the extrapolation, so converged coupling iterations give the
  // fully implicit step (at no extra solve); false: every coupling iteration is semi-implicit.
  bool relinearise = false;
  StabilisationParameters stabilisation;
  double nitsche_penalty = 0;    // gamma_N1
  double nitsche_symmetry = -1;  // gamma_N2 (+1 symmetric, -1 unsymmetric)
  // The penalty term gamma_N1 int w . (v - v_s) (and f_v, and the interface mass sent to the
  // coupler) on the interface of the last accepted step instead of the current one: the
  // coupler's M_G = H^T M_f H is then constant within a time step, so Algorithm 2's
  // iterations do not see gamma_N1 dM/dx (robust converged coupling at large gamma_N1). The
  // consistency and symmetry terms stay on the current interface.
  bool penalty_on_step_start = false;
  int threads = 1;
  int umfpack_irstep = 0;
  Ordering ordering = Ordering::Auto;
  LuStrategy strategy = LuStrategy::Auto;
  // Reuse the last LU factors as the preconditioner of BiCGSTAB on the new matrix; refactorise
  // only when BiCGSTAB needs more than krylov_max_iterations (or on the first solve).
  bool reuse_factorisation = true;
  double krylov_tolerance = 1e-10;  // relative residual
  int krylov_max_iterations = 25;
  int krylov_refactor_iterations = 8;  // a solve needing more marks the factors stale: refactorise next time
  // Refactorise as soon as a Krylov solve costs more than the average cost per solve of the
  // current factors (their factorisation included): minimises the cost per step. Costs are
  // counted in flops, not measured, so the decisions are reproducible (sparse_lu.hpp).
  bool adaptive_refactorisation = true;
};

struct StepReport {
  int iterations = 0;
  double change = 0;           // last relative velocity change
  double assembly_seconds = 0;
  double factor_seconds = 0;
  double solve_seconds = 0;
  int factorisations = 0;
  int krylov_iterations = 0;
};

class FlowSolver {
 public:
  virtual ~FlowSolver() = default;

  // --- set-up (before the first solve) ---
  virtual void add_dirichlet(const std::string& group, VelocityFunction velocity) = 0;  // strong, both components
  virtual void add_symmetry(const std::string& group) = 0;                              // u.n = 0 (axis-aligned)
  virtual void set_interface(const std::vector<std::string>& groups) = 0;               // Nitsche groups
  virtual void set_pressure_reference(const Eigen::Vector2d& point, std::function<double(double)> value) = 0;
  virtual void set_body_force(VelocityFunction force) = 0;

  // --- stepping ---
  // Solves time level `time` (= t_n + dt) from the accepted state, on the mesh at `positions`
  // (every node, current configuration), with the interface velocity per interface node
  // (interleaved, 2 * interface_nodes().size(); empty = zero). Repeatable before accept().
  virtual StepReport solve(double time, double dt, const Eigen::MatrixX2d& positions,
                           const Eigen::VectorXd& interface_velocity) = 0;
  virtual void accept() = 0;

  // --- checkpoints (after accept()) ---
  // Writes everything the next solve depends on under `prefix` (e.g. "flow.": flow.u,
  // flow.u_n, flow.x_n, flow.lu.ordering, ...) and drops the LU factors, so that the next
  // solve refactorises, exactly as a solver restored from this state does.
  virtual void save_state(StateArchive& state, const std::string& prefix) = 0;
  // On a solver set up like the saved one (same mesh, conditions and parameters), before any
  // solve: continues bit for bit as the saved one. fsi::StateError (naming the entry) when
  // the state does not fit (another element or mesh).
  virtual void load_state(const StateArchive& state, const std::string& prefix) = 0;

  // --- results of the last solve ---
  virtual const FluidMesh& mesh() const = 0;
  virtual const FlowParameters& parameters() const = 0;
  virtual int dofs() const = 0;
  virtual Eigen::MatrixX2d velocity() const = 0;  // per node
  virtual Eigen::VectorXd pressure() const = 0;   // per node (P2/P1: linear between the vertices)
  virtual const Eigen::MatrixX2d& positions() const = 0;
  // Force of the fluid on the body bounded by the groups (consistent reaction forces).
  virtual Eigen::Vector2d force(const std::vector<std::string>& groups) const = 0;
  // Interface nodes (P2/P1: vertices and edge midpoints) and their segments (local indices;
  // P2/P1: every edge split at its midpoint).
  virtual const std::vector<int>& interface_nodes() const = 0;
  virtual const IndexMatrix2& interface_segments() const = 0;
  // f_sigma = int N^T sigma n, f_v = int N^T v_f at the interface nodes (current configuration).
  virtual Eigen::VectorXd interface_traction() const = 0;
  virtual Eigen::VectorXd interface_velocity_integral() const = 0;
  // M_f = int N_i N_j dgamma over the interface in the configuration of the last solve, with
  // the quadrature of the Nitsche terms (a scalar matrix on the interface nodes): f_v = M_f v_f
  // and the penalty part of f_sigma is gamma_N1 M_f (v_f - v_s).
  virtual Eigen::SparseMatrix<double> interface_mass() const = 0;
  virtual double pressure_at(const Eigen::Vector2d& point) const = 0;  // NaN outside the mesh
  virtual Eigen::Vector2d velocity_at(const Eigen::Vector2d& point) const = 0;
};

}  // namespace fsi::fluid
