#pragma once
// Single-degree-of-freedom solid of the seed paper's appendix, as a point interface:
//   m a + (c + gamma_N1 * measure) v + k d = F_interface + F_external,
// BDF1 (v_{n+1} = (d_{n+1}-d_n)/dt, a_{n+1} = (v_{n+1}-v_n)/dt), every component
// independent (an isotropic point mass; the paper's problem is the x component). In 3D
// (dimension: 3) the same with three components, at a point or as a rigid flat plate
// (`surface`): the plate moves as one body under the sum of its nodal forces, and its
// measure is its area.
//
// Scene keys (section `solid`, model: sdof): sdof_keys.cpp.
#include <Eigen/Core>

#include "fsi/common/model_interface.hpp"
#include "fsi/common/scene_schema.hpp"
#include "fsi/common/solver_model.hpp"

namespace fsi::models {

// The keys of `solid.model: sdof` (sdof_keys.cpp).
const std::vector<schema::Key>& sdof_solid_keys();

class SdofSolid : public SolidModel {
 public:
  std::string name() const override { return "sdof"; }
  void configure(const ConfigSection& section, const SolidSetup& setup) override;
  InterfaceMeshData interface() const override;
  SolidStepResult solve_step(const StepInfo& info, const Eigen::VectorXd& interface_force) override;
  // Substeps of dt / n from the window's start, BDF1 each (the force interpolated linearly).
  bool supports_substeps() const override { return true; }
  SolidStepResult solve_window(const StepInfo& info, const Waveform& force, int substeps) override;
  std::map<std::string, double> accept_step(const StepInfo& info) override;
  bool supports_checkpoint() const override { return true; }
  bool supports_interface_mass() const override { return true; }
  // M_fs = gamma_N1 * M_G with the coupler's M_G (n x n; on a rigid body its entries sum up).
  void set_interface_mass(const NodalMatrix& m) override;
  void save_state(StateArchive& state) override;
  void load_state(const StateArchive& state) override;

 private:
  double mass_ = 1, damping_ = 0, stiffness_ = 0, measure_ = 1, interface_damping_ = 0, gamma_ = 0;
  ModelInterface interface_;
  // One BDF1 step of dt from (d, v) under the interface force; (d, v) become the new state.
  void bdf1(double dt, const Eigen::VectorXd& interface_force, Eigen::VectorXd& d, Eigen::VectorXd& v) const;
  // One value per component (2 or 3).
  Eigen::VectorXd force_, d_n_, v_n_, d_, v_, d0_, v0_;
};

}  // namespace fsi::models
