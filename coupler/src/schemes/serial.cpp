// The serial coupling scheme (Gauss-Seidel; the seed paper): the solid with F^(k), then the
// fluid with the solid's new interface state; the accelerator acts on the force F.
#include <Eigen/Core>

#include "../run_parts.hpp"

namespace fsi::coupling {
using namespace run_detail;

Coupler::Update Coupler::SerialScheme::iterate(Run& r, Step& step) {
  const int n = step.n, k = step.k;
  const StepInfo info{step.t_np1, r.time.dt, n, k};
  Update u = c.begin_iteration(r, step);
  Iterate& it = u.iterate;
  const SolidStepResult& s = it.s;
  {
    Timer t(c.times_.solid);
    it.s = c.solve_solid(r, step, info, step.force);
  }
  if (!all_finite(s.interface_displacement) || !all_finite(s.interface_velocity) ||
      !all_finite(displacement_samples(s)) || !all_finite(velocity_samples(s)))
    throw Stop{"diverged", fmt::format("solid returned a non-finite interface state at step {} iteration {}", n, k)};
  {
    Timer t(c.times_.fluid);
    it.loads = c.solve_fluid(r, step, info, displacement_samples(s), velocity_samples(s), it.d_f);
  }
  Eigen::VectorXd traction_change;
  {
    Timer t(c.times_.coupler);
    it.mass = c.map_mass(r, it.loads);
    Eigen::VectorXd f_star;
    c.window_force(r, step, it, displacement_samples(s), velocity_samples(s), f_star, traction_change);
    // r_k = -F* - F^(k); F^(k+1) = F^(k) + beta r_k is the paper's relaxation
    // (acceleration.hpp for Aitken and IQN-ILS).
    u.relaxed = r.accelerator->update(step.force, -f_star - step.force);
    r.state.mapped_mass = it.mass;  // the next solid solve's damping (Algorithm 2)
  }
  if (!all_finite(u.relaxed))
    throw Stop{"diverged", fmt::format("non-finite interface force at step {} iteration {}", n, k)};
  c.measure(step, u, traction_change);
  u.watched_residual = step.residual;
  u.watched_change = u.change;
  return u;
}

}  // namespace fsi::coupling
