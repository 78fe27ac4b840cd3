#pragma once
// The P1/P1 SUPG/PSPG/LSIC Navier-Stokes solver on a (moving) triangle mesh: boundary
// conditions, time stepping, linear solves, consistent reaction forces. No configuration
// files, no output: NavierStokesFluid (navier_stokes_fluid.hpp) wraps it for scenes.
//
// Use:
//   NavierStokesSolver solver(mesh, params);
//   solver.add_dirichlet("inlet", profile);  solver.add_dirichlet("walls", zero);
//   solver.set_interface({"flag"});                    // Nitsche groups (optional)
//   for each step:  solver.solve(t, dt, positions, interface_velocity);  (repeatable)
//                   solver.accept();
//
// Linearisation: per solve, `max_iterations` Picard (Oseen) iterations; the first one
// advects with the extrapolated velocity (BDF2: (1+w) u_n - w u_{n-1}), so one iteration
// per step is the second-order semi-implicit scheme (one factorisation per step).
#include <Eigen/Core>
#include <Eigen/SparseCore>

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "fsi/fluid/mesh.hpp"
#include "fsi/fluid/p1_element.hpp"

namespace fsi::fluid {

using VelocityFunction = std::function<Eigen::Vector2d(const Eigen::Vector2d& x, double t)>;

enum class TimeScheme { Steady, BDF1, BDF2 };

struct FlowParameters {
  double density = 1.0;
  double viscosity = 1e-3;  // dynamic
  TimeScheme scheme = TimeScheme::BDF2;
  int max_iterations = 1;   // Picard solves per step
  double tolerance = 1e-10; // stop when the relative velocity change falls below
  StabilisationParameters stabilisation;
  double nitsche_penalty = 0;    // gamma_N1
  double nitsche_symmetry = -1;  // gamma_N2 (+1 symmetric, -1 unsymmetric)
  int threads = 1;
  int umfpack_irstep = 0;
  // Reuse the last LU factors as the preconditioner of BiCGSTAB on the new matrix; refactorise
  // only when BiCGSTAB needs more than krylov_max_iterations (or on the first solve).
  bool reuse_factorisation = true;
  double krylov_tolerance = 1e-10;  // relative residual
  int krylov_max_iterations = 25;
  int krylov_refactor_iterations = 8;  // a solve needing more marks the factors stale: refactorise next time
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

class NavierStokesSolver {
 public:
  NavierStokesSolver(FluidMesh mesh, FlowParameters params);
  ~NavierStokesSolver();
  NavierStokesSolver(NavierStokesSolver&&) noexcept;
  NavierStokesSolver& operator=(NavierStokesSolver&&) noexcept;

  // --- set-up (before the first solve) ---
  void add_dirichlet(const std::string& group, VelocityFunction velocity);  // strong, both components
  void add_symmetry(const std::string& group);                              // u.n = 0 (axis-aligned groups)
  void set_interface(const std::vector<std::string>& groups);               // Nitsche groups
  void set_pressure_reference(const Eigen::Vector2d& point, std::function<double(double)> value);
  void set_body_force(VelocityFunction force);
  void set_initial_velocity(const Eigen::MatrixX2d& velocity);

  // --- stepping ---
  // Solves time level `time` (= t_n + dt) from the accepted state, on the mesh at `positions`
  // (n x 2, current configuration), with the interface velocity per interface node
  // (interleaved, 2 * interface_nodes().size(); empty = zero). Repeatable before accept().
  StepReport solve(double time, double dt, const Eigen::MatrixX2d& positions, const Eigen::VectorXd& interface_velocity);
  void accept();

  // --- results of the last solve ---
  const FluidMesh& mesh() const { return mesh_; }
  const FlowParameters& parameters() const { return params_; }
  int dofs() const { return 3 * mesh_.node_count(); }
  const Eigen::VectorXd& solution() const { return U_; }  // (u, v, p) per node
  Eigen::MatrixX2d velocity() const;
  Eigen::VectorXd pressure() const;
  const Eigen::MatrixX2d& positions() const { return X_; }
  const Eigen::MatrixX2d& accepted_positions() const { return X_n_; }
  // Force of the fluid on the body bounded by the groups: -sum of the momentum reactions
  // (residual of the volume terms) over the groups' nodes.
  Eigen::Vector2d force(const std::vector<std::string>& groups) const;
  const Eigen::VectorXd& reaction() const { return reaction_; }  // K_vol U - F_vol, 3 per node
  // Interface (Nitsche) groups.
  const std::vector<int>& interface_nodes() const { return interface_nodes_; }
  const IndexMatrix2& interface_segments() const { return interface_segments_; }  // local indices
  // f_sigma = int N^T sigma n (n = fluid outward normal), from the reaction plus the penalty
  // term: reaction + gamma_N1 int N^T (v_f - v_s); f_v = int N^T v_f. Current configuration.
  Eigen::VectorXd interface_traction() const;
  Eigen::VectorXd interface_velocity_integral() const;
  double pressure_at(const Eigen::Vector2d& point) const;  // NaN outside the mesh
  Eigen::Vector2d velocity_at(const Eigen::Vector2d& point) const;

 private:
  struct Impl;
  FluidMesh mesh_;
  FlowParameters params_;
  std::unique_ptr<Impl> impl_;
  Eigen::VectorXd U_, U_n_, U_nm1_, reaction_;
  Eigen::MatrixX2d X_, X_n_, X_nm1_;
  double dt_n_ = 0;      // last accepted step size
  double dt_trial_ = 0;  // step size of the last solve
  int accepted_ = 0;
  std::vector<int> interface_nodes_;
  IndexMatrix2 interface_segments_;
  Eigen::VectorXd interface_velocity_;  // of the last solve
  bool locate(const Eigen::Vector2d& point, int& element, Eigen::Vector3d& bary) const;
};

}  // namespace fsi::fluid
