#pragma once
// Isoparametric Taylor-Hood P2/P1 Navier-Stokes on a (moving) mesh of 6-node triangles:
// the same boundary conditions, ALE form, BDF1/BDF2, Nitsche interface and consistent
// reaction forces as the P1/P1 NavierStokesSolver (see FlowSolver), with an inf-sup stable
// element instead of PSPG, Newton or Picard linearisation, optional grad-div and SUPG.
//
//   TaylorHoodSolver solver(mesh, params);   // quadratic mesh (a linear one gets straight midpoints)
//   solver.add_dirichlet("inlet", profile);  ...  solver.set_interface({"flag"});
//   for each step: solver.solve(t, dt, positions, interface_velocity); solver.accept();
//
// Unknowns: (u, v) at every node (vertices and midpoints) at 2 i, 2 i + 1, p at the vertices
// after them (2 n + i). Interface quantities live at every interface node.
#include <Eigen/Core>
#include <Eigen/SparseCore>

#include <memory>
#include <string>
#include <vector>

#include "fsi/fluid/flow_solver.hpp"

namespace fsi::fluid {

class TaylorHoodSolver : public FlowSolver {
 public:
  TaylorHoodSolver(FluidMesh mesh, FlowParameters params);
  ~TaylorHoodSolver() override;
  TaylorHoodSolver(TaylorHoodSolver&&) noexcept;
  TaylorHoodSolver& operator=(TaylorHoodSolver&&) noexcept;

  void add_dirichlet(const std::string& group, VelocityFunction velocity) override;
  void add_symmetry(const std::string& group) override;
  void set_interface(const std::vector<std::string>& groups) override;
  void set_pressure_reference(const Eigen::Vector2d& point, std::function<double(double)> value) override;
  void set_body_force(VelocityFunction force) override;
  void set_initial_velocity(const Eigen::MatrixX2d& velocity);  // per node

  StepReport solve(double time, double dt, const Eigen::MatrixX2d& positions,
                   const Eigen::VectorXd& interface_velocity) override;
  void accept() override;
  // Checkpoints (FlowSolver): entries under `prefix` (detail::save_flow_state in
  // flow_common.hpp, element "p2p1") and the linear solver's under prefix + "lu.".
  void save_state(StateArchive& state, const std::string& prefix) override;
  void load_state(const StateArchive& state, const std::string& prefix) override;

  const FluidMesh& mesh() const override { return mesh_; }
  const FlowParameters& parameters() const override { return params_; }
  int dofs() const override { return 2 * mesh_.node_count() + mesh_.vertices(); }
  const Eigen::VectorXd& solution() const { return U_; }
  // The system of the last solve (constraints applied) and its right-hand side: for the
  // linear-solver benchmark (bench/fluid/linear_solver_bench.cpp).
  const Eigen::SparseMatrix<double>& last_matrix() const;
  const Eigen::VectorXd& last_rhs() const;
  Eigen::MatrixX2d velocity() const override;
  Eigen::VectorXd pressure() const override;
  const Eigen::MatrixX2d& positions() const override { return X_; }
  Eigen::Vector2d force(const std::vector<std::string>& groups) const override;
  const std::vector<int>& interface_nodes() const override { return interface_nodes_; }
  const IndexMatrix2& interface_segments() const override { return interface_segments_; }
  Eigen::VectorXd interface_traction() const override;
  Eigen::VectorXd interface_velocity_integral() const override;
  Eigen::SparseMatrix<double> interface_mass() const override;
  double pressure_at(const Eigen::Vector2d& point) const override;
  Eigen::Vector2d velocity_at(const Eigen::Vector2d& point) const override;

 private:
  struct Impl;
  FluidMesh mesh_;
  FlowParameters params_;
  std::unique_ptr<Impl> impl_;
  Eigen::VectorXd U_, U_n_, U_nm1_, reaction_;
  Eigen::MatrixX2d X_, X_n_, X_nm1_;
  double dt_n_ = 0, dt_trial_ = 0;
  int accepted_ = 0;
  int trial_solves_ = 0;  // solves of the current time level since the last accept()
  std::vector<int> interface_nodes_;
  IndexMatrix2 interface_segments_;
  Eigen::VectorXd interface_velocity_;
  bool locate(const Eigen::Vector2d& point, int& element, Eigen::Vector3d& bary) const;
};

}  // namespace fsi::fluid
