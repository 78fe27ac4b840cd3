#include "fsi/models/surrogate_fluid.hpp"

#include "fsi/common/interface_geometry.hpp"
#include "fsi/common/scene_reader.hpp"

namespace fsi::models {

void SurrogateFluid::configure(const ConfigSection& section, const FluidSetup&) {
  const schema::Reader s(section, surrogate_fluid_keys());
  interface_ = read_model_interface(s, "interface_measure");
  const int dim = interface_.dimension();
  const auto f = s.vector("force", dim);
  force_ = Eigen::Map<const Eigen::VectorXd>(f.data(), dim);
  added_mass_ = s.get<double>("added_mass");
  const auto& mesh = interface_.mesh;
  mass_ = nodal_interface_mass(mesh, Eigen::VectorXd());
  weight_ = mesh.lumped_measure / mesh.lumped_measure.sum();
  if (mesh.nodes() == 1) weight_.setOnes();
  const Eigen::Index n = dim * static_cast<Eigen::Index>(mesh.nodes());
  v_n_ = v_ = last_force_on_solid_ = Eigen::VectorXd::Zero(n);
}

InterfaceMeshData SurrogateFluid::interface() const { return interface_.mesh; }

FluidLoads SurrogateFluid::loads(const Eigen::VectorXd& v, const Eigen::VectorXd& acceleration) {
  const Eigen::Index d = interface_.dimension();
  for (Eigen::Index i = 0; i < weight_.size(); ++i)
    last_force_on_solid_.segment(d * i, d) = weight_[i] * (force_ - added_mass_ * acceleration.segment(d * i, d));
  FluidLoads out;
  out.traction_force = -last_force_on_solid_;
  out.velocity_integral = weight_.size() == 1 ? Eigen::VectorXd(interface_.measure * v) : apply_nodal(mass_, v);
  out.interface_mass = mass_;
  out.nonlinear_iterations = 1;
  return out;
}

FluidLoads SurrogateFluid::initial_loads(const Eigen::VectorXd&, const Eigen::VectorXd& v) {
  v_n_ = v_ = v;
  return loads(v_, Eigen::VectorXd::Zero(v.size()));
}

FluidLoads SurrogateFluid::solve_step(const StepInfo& info, const Eigen::VectorXd&, const Eigen::VectorXd& v) {
  v_ = v;
  return loads(v_, (v_ - v_n_) / info.dt);
}

FluidLoads SurrogateFluid::solve_window(const StepInfo& info, const Waveform&, const Waveform& v, int substeps) {
  const double h = info.dt / substeps, start = info.time - info.dt;
  const Eigen::Index m = v_n_.size();
  Eigen::VectorXd traction(m * substeps), velocity_integral(m * substeps);
  Eigen::VectorXd v_prev = v_n_;
  FluidLoads out;
  for (int j = 1; j <= substeps; ++j) {
    v_ = v.at(substep_time(start, info.dt, j, substeps));
    out = loads(v_, (v_ - v_prev) / h);
    traction.segment((j - 1) * m, m) = out.traction_force;
    velocity_integral.segment((j - 1) * m, m) = out.velocity_integral;
    v_prev = v_;
  }
  out.traction_samples = traction;
  out.velocity_integral_samples = velocity_integral;
  out.nonlinear_iterations = substeps;
  return out;
}

FluidLoads SurrogateFluid::solve_robin(const StepInfo& info, const Eigen::VectorXd&, const RobinCondition& robin) {
  const Eigen::Index d = interface_.dimension();
  const auto& lumped = interface_.mesh.lumped_measure;
  for (Eigen::Index j = 0; j < weight_.size(); ++j) {
    const double a = robin.coefficient[j] * (weight_.size() == 1 ? interface_.measure : lumped[j]);
    const double m = weight_[j] * added_mass_ / info.dt;
    v_.segment(d * j, d) = (a * robin.velocity.segment(d * j, d) + robin.traction.segment(d * j, d) +
                            weight_[j] * force_ + m * v_n_.segment(d * j, d)) /
                           (m + a);
  }
  return loads(v_, (v_ - v_n_) / info.dt);
}

std::map<std::string, double> SurrogateFluid::accept_step(const StepInfo&) {
  v_n_ = v_;
  const Eigen::VectorXd f = interface_.resultant(last_force_on_solid_);
  std::map<std::string, double> probes{{"force_x", f[0]}, {"force_y", f[1]}};
  if (f.size() == 3) probes["force_z"] = f[2];
  return probes;
}

void SurrogateFluid::save_state(StateArchive& state) {
  state.put("surrogate.v_n", v_n_);
  state.put("surrogate.v", v_);
  state.put("surrogate.force_on_solid", last_force_on_solid_);
}

void SurrogateFluid::load_state(const StateArchive& state) {
  const Eigen::Index n = v_.size();
  const Eigen::VectorXd v_n = state.vector("surrogate.v_n", n), v = state.vector("surrogate.v", n),
                        f = state.vector("surrogate.force_on_solid", n);
  v_n_ = v_n;
  v_ = v;
  last_force_on_solid_ = f;
}

}  // namespace fsi::models
