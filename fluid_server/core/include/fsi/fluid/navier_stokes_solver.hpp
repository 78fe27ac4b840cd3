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
#include "fsi/fluid/flow_solver.hpp"
#include "fsi/fluid/p1_element.hpp"

namespace fsi::fluid {

class NavierStokesSolver : public FlowSolver {
 public:
  NavierStokesSolver(FluidMesh mesh, FlowParameters params);
  ~NavierStokesSolver();
  NavierStokesSolver(NavierStokesSolver&&) noexcept;
  NavierStokesSolver& operator=(NavierStokesSolver&&) noexcept;

  // --- set-up (before the first solve) ---
  void add_dirichlet(const std::string& group, VelocityFunction velocity) override;  // strong, both components
  void add_symmetry(const std::string& group) override;                              // u.n = 0 (axis-aligned groups)
  void set_interface(const std::vector<std::string>& groups) override;               // Nitsche groups
  void set_pressure_reference(const Eigen::Vector2d& point, std::function<double(double)> value) override;
  void set_body_force(VelocityFunction force) override;
  void set_initial_velocity(const Eigen::MatrixX2d& velocity);

  // --- stepping ---
  // Solves time level `time` (= t_n + dt) from the accepted state, on the mesh at `positions`
  // (n x 2, current configuration), with the interface velocity per interface node
  // (interleaved, 2 * interface_nodes().size(); empty = zero). Repeatable before accept().
  StepReport solve(double time, double dt, const Eigen::MatrixX2d& positions, const Eigen::VectorXd& interface_velocity) override;
  void accept() override;
  // Checkpoints (FlowSolver): entries under `prefix` (detail::save_flow_state in
  // flow_common.hpp, element "p1p1") and the linear solver's under prefix + "lu.".
  void save_state(StateArchive& state, const std::string& prefix) override;
  void load_state(const StateArchive& state, const std::string& prefix) override;

  // --- results of the last solve ---
  const FluidMesh& mesh() const override { return mesh_; }
  const FlowParameters& parameters() const override { return params_; }
  int dofs() const override { return 3 * mesh_.node_count(); }
  const Eigen::VectorXd& solution() const { return U_; }  // (u, v, p) per node
  Eigen::MatrixX2d velocity() const override;
  Eigen::VectorXd pressure() const override;
  const Eigen::MatrixX2d& positions() const override { return X_; }
  const Eigen::MatrixX2d& accepted_positions() const { return X_n_; }
  // Force of the fluid on the body bounded by the groups: -sum of the momentum reactions
  // (residual of the volume terms) over the groups' nodes.
  Eigen::Vector2d force(const std::vector<std::string>& groups) const override;
  const Eigen::VectorXd& reaction() const { return reaction_; }  // K_vol U - F_vol, 3 per node
  // Interface (Nitsche) groups.
  const std::vector<int>& interface_nodes() const override { return interface_nodes_; }
  const IndexMatrix2& interface_segments() const override { return interface_segments_; }  // local indices
  // f_sigma = int N^T sigma n (n = fluid outward normal), from the reaction plus the penalty
  // term: reaction + gamma_N1 int N^T (v_f - v_s); f_v = int N^T v_f. Current configuration.
  Eigen::VectorXd interface_traction() const override;
  Eigen::VectorXd interface_velocity_integral() const override;
  Eigen::SparseMatrix<double> interface_mass() const override;
  double pressure_at(const Eigen::Vector2d& point) const override;  // NaN outside the mesh
  Eigen::Vector2d velocity_at(const Eigen::Vector2d& point) const override;

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
  int trial_solves_ = 0;  // solves of the current time level since the last accept()
  std::vector<int> interface_nodes_;
  IndexMatrix2 interface_segments_;
  Eigen::VectorXd interface_velocity_;  // of the last solve
  bool locate(const Eigen::Vector2d& point, int& element, Eigen::Vector3d& bary) const;
};

}  // namespace fsi::fluid
