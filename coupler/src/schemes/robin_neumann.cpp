// The explicit (generalised) Robin-Neumann scheme (coupling.scheme: robin-neumann; Fernandez,
// Mullaert & Vidrascu 2013, 2015): one pass per step, no coupling iterations.
//
// The solid's interface equation, lumped, is M (v_{n+1} - v_n) / dt + K d_{n+1} = F_{n+1}, and
// F = -f_sigma (the fluid's traction force on the solid). With A = M / dt it reads
//   f_sigma + A v_{n+1} = A v_n - K d_{n+1}.
// The fluid solves this as its Robin condition with K d_{n+1} extrapolated from the solid's
// equation of the accepted steps, K d_n = -f_n - A (v_n - v_{n-1}):
//   order 1:  f* = f_n,              v* = 2 v_n - v_{n-1}             (K d_{n+1} ~ K d_n)
//   order 2:  f* = 2 f_n - f_{n-1},  v* = 3 v_n - 3 v_{n-1} + v_{n-2}  (K d_{n+1} ~ 2 K d_n - K d_{n-1})
// so f_sigma + A v_f = A v* + f*; then the solid with the fluid's traction (Neumann). The fluid
// moves its mesh with d* = d_n + dt v*. A = (m_s / |Gamma|) / dt per unit measure, from the mass
// per interface measure the solid reports. The kinematic condition v_f = v_s is not imposed: its
// mismatch, |f_v - M_G v_s| / |M_G v_s| in the solid's nodal forces, is iterations.csv's
// kinematic_gap.
#include <Eigen/Core>

#include "../run_parts.hpp"

namespace fsi::coupling {
using namespace run_detail;

void Coupler::RobinNeumannScheme::prepare(Run& r) {
  if (!c.fluid_.supports_robin())
    throw Stop{"failed", fmt::format("coupling.scheme: robin-neumann needs a fluid that takes a Robin interface "
                                     "condition, which fluid '{}' does not (supports_robin)",
                                     c.fluid_.name())};
  const double mass_per_area = c.solid_interface_.mass_per_area;
  if (!(mass_per_area > 0))
    throw Stop{"failed", fmt::format("coupling.scheme: robin-neumann needs the solid's mass per interface measure, "
                                     "which solid '{}' does not report (InterfaceMesh.mass_per_area)",
                                     c.solid_.name())};
  fluid_values_ = r.state.d_f_prev.size();
  coefficient_ = Eigen::VectorXd::Constant(fluid_values_ / r.dim, mass_per_area / r.time.dt);
  v_nm1_ = v_nm2_ = r.state.v_s_prev;
  r.data["coupling"]["robin_neumann"] = {{"order", c.settings_.robin_neumann_order},
                                         {"coefficient", mass_per_area / r.time.dt},
                                         {"mass_per_area", mass_per_area}};
  r.log->info("explicit Robin-Neumann scheme, extrapolation order {}: Robin coefficient m_s / |Gamma| / dt = {:.6g}",
              c.settings_.robin_neumann_order, mass_per_area / r.time.dt);
}

void Coupler::RobinNeumannScheme::initial_loads(const Run& r, const FluidLoads& loads) {
  f_n_ = f_nm1_ = loads.traction_force;
  v_nm1_ = v_nm2_ = r.state.v_s_prev;
}

Coupler::Update Coupler::RobinNeumannScheme::iterate(Run& r, Step& step) {
  const int n = step.n, k = step.k;
  const StepInfo info{step.t_np1, r.time.dt, n, k};
  Update u = c.begin_iteration(r, step);
  Iterate& it = u.iterate;
  const Eigen::VectorXd& v_n = r.state.v_s_prev;
  const bool second = c.settings_.robin_neumann_order == 2;
  const Eigen::VectorXd v_star =
      second ? Eigen::VectorXd(3 * v_n - 3 * v_nm1_ + v_nm2_) : Eigen::VectorXd(2 * v_n - v_nm1_);
  RobinCondition robin;
  {
    Timer t(c.times_.coupler);
    it.d_f = c.map_.to_fluid(r.state.d_s_prev + r.time.dt * v_star);
    robin = RobinCondition{coefficient_, c.map_.to_fluid(v_star), second ? Eigen::VectorXd(2 * f_n_ - f_nm1_) : f_n_};
  }
  {
    Timer t(c.times_.fluid);
    it.loads = c.fluid_.solve_robin(info, it.d_f, robin);
  }
  Eigen::VectorXd fv;
  {
    Timer t(c.times_.coupler);
    it.mass = c.map_mass(r, it.loads);
    it.traction = c.map_.to_solid(it.loads.traction_force);  // all of f_sigma is physical: no penalty part
    fv = c.map_.to_solid(it.loads.velocity_integral);
    step.force = -it.traction;  // F_{n+1}: the solid's load, what it is given
  }
  if (!all_finite(step.force)) throw Stop{"diverged", fmt::format("non-finite interface force at step {}", n)};
  {
    Timer t(c.times_.solid);
    it.s = c.solid_.solve_step(info, step.force);
  }
  const SolidStepResult& s = it.s;
  if (!all_finite(s.interface_displacement) || !all_finite(s.interface_velocity))
    throw Stop{"diverged", fmt::format("solid returned a non-finite interface state at step {}", n)};
  u.relaxed = step.force;
  r.state.mapped_mass = it.mass;
  c.measure(step, u, Eigen::VectorXd::Zero(step.force.size()));
  const Eigen::VectorXd mv = apply_nodal(c.physical_mass(s.interface_displacement, it.mass), s.interface_velocity);
  u.columns = {(fv - mv).norm() / std::max(mv.norm(), c.settings_.residual_floor)};
  return u;
}

void Coupler::RobinNeumannScheme::accept(const Run& r, const Step& step) {
  v_nm2_ = v_nm1_;
  v_nm1_ = r.state.v_s_prev;
  f_nm1_ = f_n_;
  f_n_ = step.last.loads.traction_force;
}

void Coupler::RobinNeumannScheme::save(StateArchive& a) const {
  a.put("robin_neumann.f_n", f_n_);
  a.put("robin_neumann.f_nm1", f_nm1_);
  a.put("robin_neumann.v_nm1", v_nm1_);
  a.put("robin_neumann.v_nm2", v_nm2_);
}

bool Coupler::RobinNeumannScheme::has_history(const StateArchive& a) const { return a.has("robin_neumann.f_n"); }

void Coupler::RobinNeumannScheme::load(const StateArchive& a) {
  if (!a.has("robin_neumann.f_n"))
    throw Stop{"failed",
               "the checkpoint holds no Robin-Neumann history (robin_neumann.f_n): a run of another coupling.scheme "
               "cannot be resumed into scheme robin-neumann (a fork, fsi run --from, can)"};
  f_n_ = a.vector("robin_neumann.f_n", fluid_values_);
  f_nm1_ = a.vector("robin_neumann.f_nm1", f_n_.size());
  v_nm1_ = a.vector("robin_neumann.v_nm1", v_nm1_.size());
  v_nm2_ = a.vector("robin_neumann.v_nm2", v_nm1_.size());
}

}  // namespace fsi::coupling
