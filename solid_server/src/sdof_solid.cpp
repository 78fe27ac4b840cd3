#include "fsi/models/sdof_solid.hpp"

#include <fmt/format.h>

#include "fsi/common/scene_reader.hpp"

namespace fsi::models {
namespace {
Eigen::VectorXd vector_of(const schema::Reader& r, const std::string& key, int dim) {
  const auto v = r.vector(key, dim);
  return Eigen::Map<const Eigen::VectorXd>(v.data(), dim);
}
}  // namespace

void SdofSolid::configure(const ConfigSection& section, const SolidSetup& setup) {
  const schema::Reader s(section, sdof_solid_keys());
  mass_ = s.get<double>("mass");
  damping_ = s.get<double>("damping");
  stiffness_ = s.get<double>("stiffness");
  interface_ = read_model_interface(s, "interface_measure");
  measure_ = interface_.measure;
  const int dim = interface_.dimension();
  force_ = vector_of(s, "force", dim);
  d0_ = vector_of(s, "initial_displacement", dim);
  v0_ = vector_of(s, "initial_velocity", dim);
  gamma_ = setup.interface_damping;
  interface_damping_ = gamma_ * measure_;  // M_fs = gamma_N1 * M_G (until the coupler gives its M_G)
  d_n_ = d_ = d0_;
  v_n_ = v_ = v0_;
}

void SdofSolid::set_interface_mass(const NodalMatrix& m) {
  const Eigen::Index n = static_cast<Eigen::Index>(interface_.mesh.nodes());
  if (m.rows() != n || m.cols() != n)
    throw std::invalid_argument(fmt::format("sdof: interface mass must be {} x {} (its interface nodes), got {} x {}",
                                            n, n, m.rows(), m.cols()));
  // A rigid body: the damping of a uniform velocity, 1^T M_G 1 (M_G's only entry for a point).
  interface_damping_ = gamma_ * (n == 1 ? m.coeff(0, 0) : m.sum());
}

InterfaceMeshData SdofSolid::interface() const {
  InterfaceMeshData data = interface_.mesh;
  data.initial_displacement = interface_.uniform(d0_);
  data.initial_velocity = interface_.uniform(v0_);
  data.mass_per_area = mass_ / measure_;
  return data;
}

void SdofSolid::bdf1(double dt, const Eigen::VectorXd& interface_force, Eigen::VectorXd& d, Eigen::VectorXd& v) const {
  const double c = damping_ + interface_damping_;
  // m (d' - d - dt v)/dt^2 + c (d' - d)/dt + k d' = F
  const double lhs = mass_ / (dt * dt) + c / dt + stiffness_;
  const Eigen::VectorXd rhs =
      interface_.resultant(interface_force) + force_ + mass_ * (d / (dt * dt) + v / dt) + c * d / dt;
  const Eigen::VectorXd d_new = rhs / lhs;
  v = (d_new - d) / dt;
  d = d_new;
}

SolidStepResult SdofSolid::solve_step(const StepInfo& info, const Eigen::VectorXd& interface_force) {
  d_ = d_n_;
  v_ = v_n_;
  bdf1(info.dt, interface_force, d_, v_);
  return {interface_.uniform(d_), interface_.uniform(v_), 1, {}, {}};
}

SolidStepResult SdofSolid::solve_window(const StepInfo& info, const Waveform& force, int substeps) {
  const double h = info.dt / substeps, start = info.time - info.dt;
  d_ = d_n_;
  v_ = v_n_;
  SolidStepResult out;
  const Eigen::Index m = static_cast<Eigen::Index>(interface_.mesh.values());
  out.displacement_samples.resize(m * substeps);
  out.velocity_samples.resize(m * substeps);
  for (int j = 1; j <= substeps; ++j) {
    bdf1(h, force.at(substep_time(start, info.dt, j, substeps)), d_, v_);
    out.displacement_samples.segment((j - 1) * m, m) = interface_.uniform(d_);
    out.velocity_samples.segment((j - 1) * m, m) = interface_.uniform(v_);
  }
  out.interface_displacement = interface_.uniform(d_);
  out.interface_velocity = interface_.uniform(v_);
  out.newton_iterations = substeps;
  return out;
}

std::map<std::string, double> SdofSolid::accept_step(const StepInfo&) {
  d_n_ = d_;
  v_n_ = v_;
  std::map<std::string, double> probes{{"d_x", d_[0]}, {"d_y", d_[1]}, {"v_x", v_[0]}, {"v_y", v_[1]}};
  if (d_.size() == 3) probes["d_z"] = d_[2], probes["v_z"] = v_[2];
  return probes;
}

void SdofSolid::save_state(StateArchive& state) {
  state.put("sdof.d_n", Eigen::VectorXd(d_n_));
  state.put("sdof.v_n", Eigen::VectorXd(v_n_));
}

void SdofSolid::load_state(const StateArchive& state) {
  const Eigen::Index dim = interface_.dimension();
  d_n_ = d_ = state.vector("sdof.d_n", dim);
  v_n_ = v_ = state.vector("sdof.v_n", dim);
}

}  // namespace fsi::models
