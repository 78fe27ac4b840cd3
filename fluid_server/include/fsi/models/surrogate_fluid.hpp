#pragma once
// Surrogate fluid for the coupler's model problems, in 2D or 3D. At a point interface (one
// node at the origin) or on a rigid flat plate (3D, `surface`), it returns the loads of a
// fluid that
//   - pushes the solid with a constant force `force` (the paper's appendix: F = 1.282),
//   - resists the BDF1 acceleration of the interface velocity with an added mass m_a:
//       force on the solid = force - added_mass (v_{n+1} - v_n) / dt,
//   - moves with the solid: its interface velocity is the solid velocity it was given.
// On a plate each node takes its share of the force by its lumped area (w_i = A_i / A) and
// resists its own acceleration with the added mass w_i m_a, so a rigid motion feels the
// resultant above. In the protocol's terms: f_sigma = -(force on the solid), f_v = M_G v.
//
// Scene keys (section `fluid`, model: surrogate): force (0; number = x, or [fx, fy(, fz)]),
//   added_mass (0), interface_measure (1), dimension (2), surface (3D plate)
#include <Eigen/Core>

#include "fsi/common/model_interface.hpp"
#include "fsi/common/scene_schema.hpp"
#include "fsi/common/solver_model.hpp"

namespace fsi::models {

// The keys of `fluid.model: surrogate` (surrogate_keys.cpp).
const std::vector<schema::Key>& surrogate_fluid_keys();

class SurrogateFluid : public FluidModel {
 public:
  std::string name() const override { return "surrogate"; }
  void configure(const ConfigSection& section, const FluidSetup& setup) override;
  InterfaceMeshData interface() const override;
  FluidLoads initial_loads(const Eigen::VectorXd& d, const Eigen::VectorXd& v) override;
  FluidLoads solve_step(const StepInfo& info, const Eigen::VectorXd& d, const Eigen::VectorXd& v) override;
  // Substeps of dt / n: the velocity interpolated linearly at each substep's end, its BDF1
  // acceleration over the substep.
  bool supports_substeps() const override { return true; }
  FluidLoads solve_window(const StepInfo& info, const Waveform& d, const Waveform& v, int substeps) override;
  // The Robin condition in closed form, node by node: with the force on the solid
  // w_j (F - m_a (v_j - v_n,j) / dt) = -f_sigma_j, v_j (w_j m_a / dt + A_j) = A_j v*_j + f*_j +
  // w_j F + w_j m_a v_n,j / dt.
  bool supports_robin() const override { return true; }
  FluidLoads solve_robin(const StepInfo& info, const Eigen::VectorXd& d, const RobinCondition& robin) override;
  std::map<std::string, double> accept_step(const StepInfo& info) override;
  // Checkpoints: "surrogate.v_n" (accepted interface velocity), "surrogate.v" (of the last
  // solve), "surrogate.force_on_solid" (of the last solve), dimension x nodes values each.
  bool supports_checkpoint() const override { return true; }
  void save_state(StateArchive& state) override;
  void load_state(const StateArchive& state) override;

 private:
  FluidLoads loads(const Eigen::VectorXd& v, const Eigen::VectorXd& acceleration);
  ModelInterface interface_;
  NodalMatrix mass_;        // M_G of the interface (fixed: the plate only translates)
  Eigen::VectorXd weight_;  // each node's share of the force (1 at a point)
  Eigen::VectorXd force_;
  double added_mass_ = 0;
  Eigen::VectorXd v_n_, v_, last_force_on_solid_;  // nodal, interleaved
};

}  // namespace fsi::models
