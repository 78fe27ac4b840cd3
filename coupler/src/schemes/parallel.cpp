// The parallel coupling scheme (Jacobi; preCICE's parallel implicit coupling): the solid with
// F^(k) and the fluid with the interface state x^(k) = (d^(k), v^(k)) at the same time; the
// accelerator acts on the stacked, scaled [d; v; F]. With one iteration per step it is a
// parallel explicit scheme: the fluid gets the predicted d_n + dt v_n, v_n.
#include <Eigen/Core>
#include <future>
#include <limits>

#include "../run_parts.hpp"

namespace fsi::coupling {
using namespace run_detail;

std::vector<std::string> Coupler::ParallelScheme::columns() const { return {"interface_gap"}; }

// The fluid's first interface state: the accepted one, its displacement extrapolated.
void Coupler::ParallelScheme::begin_step(const Run& r, Step& step) const {
  if (r.n_solid == 1) {
    step.x_d = r.state.d_s_prev + r.time.dt * r.state.v_s_prev;
    step.x_v = r.state.v_s_prev;
    return;
  }
  // Waveforms: the same extrapolation at every substep's end.
  step.x_d.resize(r.nv * r.n_solid);
  for (int j = 1; j <= r.n_solid; ++j)
    step.x_d.segment((j - 1) * r.nv, r.nv) = r.state.d_s_prev + (r.time.dt * j / r.n_solid) * r.state.v_s_prev;
  step.x_v = repeated(r.state.v_s_prev, r.n_solid);
}

// The interface state must have converged too: its change below the measures' smallest limit.
bool Coupler::ParallelScheme::converged(const Update& u) const {
  double limit = std::numeric_limits<double>::infinity();
  for (const auto& m : c.settings_.measures) limit = std::min(limit, m.limit);
  return u.gap < limit;
}

void Coupler::ParallelScheme::save(StateArchive& a) const {
  a.put("parallel.scale", std::vector<double>(scale_, scale_ + 3));
  a.put("parallel.peak", std::vector<double>(peak_, peak_ + 3));
}

void Coupler::ParallelScheme::load(const StateArchive& a) {
  if (!a.has("parallel.scale")) return;
  const Eigen::VectorXd scale = a.vector("parallel.scale", 3);
  std::copy(scale.data(), scale.data() + 3, scale_);
  // Checkpoints before the floor: the scale is the largest known.
  const Eigen::VectorXd peak = a.has("parallel.peak") ? a.vector("parallel.peak", 3) : scale;
  std::copy(peak.data(), peak.data() + 3, peak_);
}

// Parallel (Jacobi): the solid with F^(k) and the fluid with x^(k) = (d^(k), v^(k)) at once,
// then the accelerator on the stacked, scaled [d; v; F] with the residual
// [d_s - d^(k); v_s - v^(k); -F*(x^(k)) - F^(k)].
Coupler::Update Coupler::ParallelScheme::iterate(Run& r, Step& step) {
  const int n = step.n, k = step.k;
  const StepInfo info{step.t_np1, r.time.dt, n, k};
  Update u = c.begin_iteration(r, step);
  Iterate& it = u.iterate;
  // Each server has its own connection: the solid's request goes from a second thread while
  // this one waits for the fluid; both wait for the other before anything is thrown.
  auto solid_job = std::async(std::launch::async, [&] {
    Timer t(c.times_.solid);
    return c.solve_solid(r, step, info, step.force);
  });
  try {
    Timer t(c.times_.fluid);
    it.loads = c.solve_fluid(r, step, info, step.x_d, step.x_v, it.d_f);
  } catch (...) {
    solid_job.wait();
    throw;
  }
  it.s = solid_job.get();
  const SolidStepResult& s = it.s;
  if (!all_finite(s.interface_displacement) || !all_finite(s.interface_velocity) ||
      !all_finite(displacement_samples(s)) || !all_finite(velocity_samples(s)))
    throw Stop{"diverged", fmt::format("solid returned a non-finite interface state at step {} iteration {}", n, k)};
  Eigen::VectorXd traction_change;
  {
    Timer t(c.times_.coupler);
    it.mass = c.map_mass(r, it.loads);
    // F* of the interface state the fluid was given.
    Eigen::VectorXd f_star;
    c.window_force(r, step, it, step.x_d, step.x_v, f_star, traction_change);
    stacked_update(r, step, u, -f_star - step.force);
    r.state.mapped_mass = it.mass;
  }
  if (!all_finite(u.relaxed) || !all_finite(u.next_d) || !all_finite(u.next_v))
    throw Stop{"diverged", fmt::format("non-finite interface state at step {} iteration {}", n, k)};
  c.measure(step, u, traction_change);
  u.gap = (u.next_d - step.x_d).norm() / std::max(u.next_d.norm(), c.settings_.residual_floor);
  // Growth is watched on the stacked, scaled [d; v; F] (its force part may start at 0).
  u.watched_residual = u.stacked_residual;
  u.watched_change = u.stacked_change;
  u.columns = {u.gap};
  return u;
}

// x^(k+1) from the accelerator on the stacked [d; v; F], each block divided by its scale: the
// size of the block (of x^(k) or of its new value, the larger) when it first is nonzero,
// renewed at a step's first iteration when the size has moved by more than a factor 10 (the
// accelerator then starts afresh: its secant pairs are in the old scaling). A scale never
// drops below kScaleFloor times the largest it has had: a block that decays to rest (the
// velocity of a steady state) would otherwise be measured against its own round-off, its
// relative residual would stay O(1) however converged the step, and the quasi-Newton history
// would fit noise.
namespace {
constexpr double kScaleFloor = 1e-3;  // of a block's largest scale (stacked_update)
}  // namespace

void Coupler::ParallelScheme::stacked_update(Run& r, const Step& step, Update& u, const Eigen::VectorXd& r_force) {
  const SolidStepResult& s = u.iterate.s;
  const Eigen::VectorXd* x[3] = {&step.x_d, &step.x_v, &step.force};
  const Eigen::VectorXd res[3] = {displacement_samples(s) - step.x_d, velocity_samples(s) - step.x_v, r_force};
  // The blocks' sizes: the solid's samples for d and v, the fluid's for F (all equal without
  // substeps).
  const Eigen::Index size[3] = {step.x_d.size(), step.x_v.size(), step.force.size()};
  const Eigen::Index offset[3] = {0, size[0], size[0] + size[1]};
  double* scale = scale_;
  if (step.k == 1) {
    bool renewed = false;
    for (int b = 0; b < 3; ++b) {
      const double block = std::max({x[b]->norm(), (*x[b] + res[b]).norm(), kScaleFloor * peak_[b]});
      if (block > c.settings_.residual_floor && (scale[b] == 0 || block > 10 * scale[b] || block < 0.1 * scale[b])) {
        scale[b] = block, renewed = true;
        peak_[b] = std::max(peak_[b], block);
      }
    }
    if (renewed && step.n > 1) {
      r.accelerator = make_accelerator(c.settings_);
      r.accelerator->begin_step();
    }
  }
  const Eigen::Index total = size[0] + size[1] + size[2];
  Eigen::VectorXd xs(total), rs(total);
  for (int b = 0; b < 3; ++b) {
    const double w = scale[b] > 0 ? 1 / scale[b] : 1.0;
    xs.segment(offset[b], size[b]) = w * *x[b];
    rs.segment(offset[b], size[b]) = w * res[b];
  }
  const Eigen::VectorXd y = r.accelerator->update(xs, rs);
  u.stacked_change = (y - xs).norm();
  u.stacked_residual = u.stacked_change / std::max(y.norm(), c.settings_.residual_floor);
  Eigen::VectorXd* out[3] = {&u.next_d, &u.next_v, &u.relaxed};
  for (int b = 0; b < 3; ++b) *out[b] = (scale[b] > 0 ? scale[b] : 1.0) * y.segment(offset[b], size[b]);
}

}  // namespace fsi::coupling
