#include "fsi/models/sdof_solid.hpp"

#include "fsi/common/scene_reader.hpp"

namespace fsi::models {
namespace {
Eigen::Vector2d vector2(const schema::Reader& r, const std::string& key) {
  const auto v = r.vector2(key);
  return {v[0], v[1]};
}
}  // namespace

void SdofSolid::configure(const ConfigSection& section, const SolidSetup& setup) {
  const schema::Reader s(section, sdof_solid_keys());
  mass_ = s.get<double>("mass");
  damping_ = s.get<double>("damping");
  stiffness_ = s.get<double>("stiffness");
  measure_ = s.get<double>("interface_measure");
  force_ = vector2(s, "force");
  d0_ = vector2(s, "initial_displacement");
  v0_ = vector2(s, "initial_velocity");
  gamma_ = setup.interface_damping;
  interface_damping_ = gamma_ * measure_;  // M_fs = gamma_N1 * M_G (until the coupler gives its M_G)
  d_n_ = d_ = d0_;
  v_n_ = v_ = v0_;
}

void SdofSolid::set_interface_mass(const NodalMatrix& m) {
  if (m.rows() != 1 || m.cols() != 1)
    throw std::invalid_argument("sdof: interface mass must be 1 x 1 (one interface node), got " +
                                std::to_string(m.rows()) + " x " + std::to_string(m.cols()));
  interface_damping_ = gamma_ * m.coeff(0, 0);
}

InterfaceMeshData SdofSolid::interface() const {
  InterfaceMeshData data;
  data.node_ids = {0};
  data.coordinates = Eigen::MatrixX2d::Zero(1, 2);
  data.lumped_measure = Eigen::VectorXd::Constant(1, measure_);
  data.initial_displacement = d0_;
  data.initial_velocity = v0_;
  data.mass_per_area = mass_ / measure_;
  return data;
}

SolidStepResult SdofSolid::solve_step(const StepInfo& info, const Eigen::VectorXd& interface_force) {
  const double dt = info.dt;
  const double c = damping_ + interface_damping_;
  // m (d - d_n - dt v_n)/dt^2 + c (d - d_n)/dt + k d = F
  const double lhs = mass_ / (dt * dt) + c / dt + stiffness_;
  const Eigen::Vector2d rhs =
      interface_force.head<2>() + force_ + mass_ * (d_n_ / (dt * dt) + v_n_ / dt) + c * d_n_ / dt;
  d_ = rhs / lhs;
  v_ = (d_ - d_n_) / dt;
  return {d_, v_, 1};
}

std::map<std::string, double> SdofSolid::accept_step(const StepInfo&) {
  d_n_ = d_;
  v_n_ = v_;
  return {{"d_x", d_[0]}, {"d_y", d_[1]}, {"v_x", v_[0]}, {"v_y", v_[1]}};
}

void SdofSolid::save_state(StateArchive& state) {
  state.put("sdof.d_n", Eigen::VectorXd(d_n_));
  state.put("sdof.v_n", Eigen::VectorXd(v_n_));
}

void SdofSolid::load_state(const StateArchive& state) {
  d_n_ = d_ = state.vector("sdof.d_n", 2);
  v_n_ = v_ = state.vector("sdof.v_n", 2);
}

}  // namespace fsi::models
