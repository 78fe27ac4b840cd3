#include "fsi/models/surrogate_fluid.hpp"

#include "fsi/common/scene_reader.hpp"

namespace fsi::models {
namespace {
Eigen::Vector2d vector2(const schema::Reader& r, const std::string& key) {
  const auto v = r.vector2(key);
  return {v[0], v[1]};
}
}  // namespace

void SurrogateFluid::configure(const ConfigSection& section, const FluidSetup&) {
  const schema::Reader s(section, surrogate_fluid_keys());
  force_ = vector2(s, "force");
  added_mass_ = s.get<double>("added_mass");
  measure_ = s.get<double>("interface_measure");
}

InterfaceMeshData SurrogateFluid::interface() const {
  InterfaceMeshData data;
  data.node_ids = {0};
  data.coordinates = Eigen::MatrixX2d::Zero(1, 2);
  data.lumped_measure = Eigen::VectorXd::Constant(1, measure_);
  return data;
}

FluidLoads SurrogateFluid::loads(const Eigen::Vector2d& v, const Eigen::Vector2d& acceleration) {
  last_force_on_solid_ = force_ - added_mass_ * acceleration;
  FluidLoads out;
  out.traction_force = -last_force_on_solid_;
  out.velocity_integral = measure_ * v;
  out.interface_mass.resize(1, 1);
  out.interface_mass.insert(0, 0) = measure_;
  out.nonlinear_iterations = 1;
  return out;
}

FluidLoads SurrogateFluid::initial_loads(const Eigen::VectorXd&, const Eigen::VectorXd& v) {
  v_n_ = v_ = v.head<2>();
  return loads(v_, Eigen::Vector2d::Zero());
}

FluidLoads SurrogateFluid::solve_step(const StepInfo& info, const Eigen::VectorXd&, const Eigen::VectorXd& v) {
  v_ = v.head<2>();
  return loads(v_, (v_ - v_n_) / info.dt);
}

std::map<std::string, double> SurrogateFluid::accept_step(const StepInfo&) {
  v_n_ = v_;
  return {{"force_x", last_force_on_solid_[0]}, {"force_y", last_force_on_solid_[1]}};
}

void SurrogateFluid::save_state(StateArchive& state) {
  state.put("surrogate.v_n", Eigen::VectorXd(v_n_));
  state.put("surrogate.v", Eigen::VectorXd(v_));
  state.put("surrogate.force_on_solid", Eigen::VectorXd(last_force_on_solid_));
}

void SurrogateFluid::load_state(const StateArchive& state) {
  const Eigen::VectorXd v_n = state.vector("surrogate.v_n", 2), v = state.vector("surrogate.v", 2),
                        f = state.vector("surrogate.force_on_solid", 2);
  v_n_ = v_n;
  v_ = v;
  last_force_on_solid_ = f;
}

}  // namespace fsi::models
