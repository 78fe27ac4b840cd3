#pragma once
// Surrogate fluid for the coupler's model problems. At a point interface (one node at
// the origin) it returns the loads of a fluid that
//   - pushes the solid with a constant force `force` (the paper's appendix: F = 1.282),
//   - resists the BDF1 acceleration of the interface velocity with an added mass m_a:
//       force on the solid = force - added_mass (v_{n+1} - v_n) / dt,
//   - moves with the solid: its interface velocity is the solid velocity it was given.
// In the protocol's terms: f_sigma = -(force on the solid), f_v = measure * v.
//
// Scene keys (section `fluid`, model: surrogate): force (0; number = x, or [fx, fy]),
//   added_mass (0), interface_measure (1)
#include <Eigen/Core>

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
  std::map<std::string, double> accept_step(const StepInfo& info) override;
  // Checkpoints: "surrogate.v_n" (accepted interface velocity), "surrogate.v" (of the last
  // solve), "surrogate.force_on_solid" (of the last solve), 2 values each.
  bool supports_checkpoint() const override { return true; }
  void save_state(StateArchive& state) override;
  void load_state(const StateArchive& state) override;

 private:
  FluidLoads loads(const Eigen::Vector2d& v, const Eigen::Vector2d& acceleration);
  Eigen::Vector2d force_ = Eigen::Vector2d::Zero();
  double added_mass_ = 0, measure_ = 1;
  Eigen::Vector2d v_n_ = Eigen::Vector2d::Zero(), v_ = Eigen::Vector2d::Zero();
  Eigen::Vector2d last_force_on_solid_ = Eigen::Vector2d::Zero();
};

}  // namespace fsi::models
