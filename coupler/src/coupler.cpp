#include "fsi/coupling/coupler.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <future>
#include <limits>
#include <tuple>

#include "fsi/common/interface_geometry.hpp"
#include "fsi/common/write_check.hpp"
#include "fsi/coupling/predictor.hpp"
#include "run_parts.hpp"

namespace fsi::coupling {
using namespace run_detail;

std::atomic<bool>& Coupler::interrupt_flag() {
  static std::atomic<bool> flag{false};
  return flag;
}

Coupler::Coupler(SolidModel& solid, FluidModel& fluid, const Scene& scene, std::filesystem::path out_dir)
    : solid_(solid), fluid_(fluid), scene_(scene), out_dir_(std::move(out_dir)) {}

Eigen::VectorXd Coupler::robin_force(const Eigen::VectorXd& traction, const Eigen::VectorXd& velocity_integral,
                                     const Eigen::VectorXd& solid_velocity, const Eigen::VectorXd& solid_displacement,
                                     const NodalMatrix& mapped_mass) const {
  // traction = H^T f_sigma = H^T R + gamma_f (H^T f_v - M_G v_s): the fluid's force with its
  // penalty gamma_f. Algorithm 2: F* = H^T R - gamma_N1 M_G v_s (the solid adds gamma_N1 C v);
  // Algorithm 1: F* = H^T R + gamma_f (M_A1 - M_G) v_s (zero extra with the consistent M_A1).
  const double gamma = settings_.gamma_n1, gamma_f = settings_.gamma_f;
  if (settings_.algorithm == Algorithm::ImplicitSolidVelocity) {
    if (gamma_f == gamma) return traction - gamma * velocity_integral;
    return traction - gamma_f * velocity_integral +
           (gamma_f - gamma) * apply_nodal(physical_mass(solid_displacement, mapped_mass), solid_velocity);
  }
  if (gamma_f == 0) return traction;
  return traction +
         gamma_f * (apply_nodal(algorithm1_mass(solid_displacement, mapped_mass), solid_velocity) - velocity_integral);
}

NodalMatrix Coupler::algorithm1_mass(const Eigen::VectorXd& solid_displacement, const NodalMatrix& mapped_mass) const {
  if (settings_.robin_mass == RobinMass::Consistent && mapped_mass.rows() > 0) return mapped_mass;
  return nodal_interface_mass(solid_interface_, solid_displacement);  // the solid's polyline, current configuration
}

NodalMatrix Coupler::solid_damping_mass(const NodalMatrix& mapped_mass) const {
  if (settings_.algorithm != Algorithm::ImplicitSolidVelocity || settings_.gamma_n1 == 0) return NodalMatrix();
  if (consistent_damping_ && mapped_mass.rows() > 0) return mapped_mass;
  return nodal_interface_mass(solid_interface_, Eigen::VectorXd());  // the solid's own, reference configuration
}

NodalMatrix Coupler::physical_mass(const Eigen::VectorXd& solid_displacement, const NodalMatrix& mapped_mass) const {
  if (mapped_mass.rows() > 0) return mapped_mass;
  return nodal_interface_mass(solid_interface_, solid_displacement);  // a fluid without M_f: the solid's polyline
}
RunOutcome Coupler::run(RunReport& report) {
  RunOutcome out;
  const double start = now();
  // Where an error happened, for its message: configuring, the initial state, or a step.
  enum class Phase { Configuring, Starting, Stepping } phase = Phase::Configuring;
  const auto at = [&] {
    return phase == Phase::Configuring ? std::string("while configuring")
           : phase == Phase::Starting  ? std::string("while setting up the initial state")
                                       : fmt::format("at step {}", out.steps + 1);
  };
  try {
    // 1. Read the scene's coupling part; configure both solvers.
    InterfaceMeshData fluid_interface;
    const TimeSettings time = configure(fluid_interface);
    phase = Phase::Starting;
    describe_setup(report.data(), time, fluid_interface);
    // 2. Initial state: the newest checkpoint (resume, fork), or the scene's initial state
    //    and the predictor's F_0 = -F*(initial fluid state).
    Run r(*this, time, fluid_interface, out, report.data(), start);
    r.scheme = make_scheme();
    report.data()["coupling"]["scheme"] = r.scheme->name();
    r.scheme->prepare(r);
    start_state(r);
    // 3. Time loop.
    open_tables(r);
    phase = Phase::Stepping;
    for (int n = out.steps + 1; n <= time.steps; ++n) {
      Step step = begin_step(r, n);
      for (; step.k <= settings_.max_iterations; ++step.k) {
        const Update u = r.scheme->iterate(r, step);
        r.progress->within(n, fmt::format("iteration {} residual {:.2e}", step.k, step.residual));
        const bool met = measures_met(step, u);
        if (finish_iteration(r, step, u, met)) {
          step.converged = true;
          break;
        }
      }
      check_unconverged(step);
      accept_step(r, step);
    }
    out.status = "completed";
  } catch (const Stop& stop) {
    out.status = stop.status;
    out.reason = stop.reason;
  } catch (const ConfigError& e) {
    out.status = "failed";
    out.reason = std::string("configuration: ") + e.what();
  } catch (const SolverError& e) {
    out.status = "diverged";
    out.reason = fmt::format("solver failed {}: {}", at(), e.what());
  } catch (const std::exception& e) {
    out.status = "failed";
    out.write_failed = is_write_failure(e.what());
    // a write fails after the last step in probes.csv (its row, output or checkpoint, or the next row)
    out.reason = fmt::format(
        "{}: {}", out.write_failed && phase == Phase::Stepping ? fmt::format("after step {}", out.steps) : at(),
        e.what());
  }
  times_.total = now() - start;
  return out;
}

// The physical traction H^T R = f_sigma - gamma_f (f_v - M_f v) of a fluid solve given the
// interface state (d, v) (the fluid's reaction, without its penalty part) into it.traction,
// and its mismatch with what the solid felt: its load F^(k) minus its own Robin damping
// gamma_N1 C v_s.
Eigen::VectorXd Coupler::traction_mismatch(Iterate& it, const Eigen::VectorXd& fs, const Eigen::VectorXd& fv,
                                           const Eigen::VectorXd& d, const Eigen::VectorXd& v,
                                           const Eigen::VectorXd& force) const {
  const double gamma_f = settings_.gamma_f;
  it.traction = gamma_f > 0 ? Eigen::VectorXd(fs - gamma_f * (fv - apply_nodal(physical_mass(d, it.mass), v))) : fs;
  Eigen::VectorXd mismatch = it.traction + force;
  if (it.damping.rows() > 0) mismatch -= settings_.gamma_n1 * apply_nodal(it.damping, it.s.interface_velocity);
  return mismatch;
}

SolidStepResult Coupler::solve_solid(const Run& r, const Step& step, const StepInfo& info,
                                     const Eigen::VectorXd& force) {
  if (r.n_solid == 1) return solid_.solve_step(info, end_of(force, r.nv));
  // The force's waveform: the accepted F_n at the window's start, then the fluid's samples.
  Waveform w = Waveform::window(step.t_np1 - r.time.dt, r.time.dt, end_of(r.state.force_n, r.nv), force, r.n_fluid);
  // and, once known, the previous window's end (F_{n-1}), for a second-order solid's
  // higher-degree interpolation near the window's start.
  if (r.state.forces_known >= 2) {
    w.times.insert(w.times.begin(), step.t_np1 - 2 * r.time.dt);
    w.values.insert(w.values.begin(), end_of(r.state.force_nm1, r.nv));
  }
  SolidStepResult s = solid_.solve_window(info, w, r.n_solid);
  const Eigen::Index m = r.nv * r.n_solid;
  if (s.displacement_samples.size() != m || s.velocity_samples.size() != m)
    throw Stop{"failed", fmt::format("solid '{}' returned {} interface samples of its {} substeps, expected {}",
                                     solid_.name(), s.displacement_samples.size(), r.n_solid, m)};
  return s;
}

FluidLoads Coupler::solve_fluid(const Run& r, const Step& step, const StepInfo& info, const Eigen::VectorXd& d,
                                const Eigen::VectorXd& v, Eigen::VectorXd& d_f) {
  d_f = map_.to_fluid(end_of(d, r.nv));
  if (r.n_fluid == 1) return fluid_.solve_step(info, d_f, map_.to_fluid(end_of(v, r.nv)));
  // The interface state's waveforms on the fluid's nodes: the accepted state at the window's
  // start, then the solid-side samples mapped.
  const Eigen::Index nv = r.nv;
  const Eigen::VectorXd start_d = r.state.d_f_prev, start_v = map_.to_fluid(r.state.v_s_prev);
  const Eigen::Index mf = start_d.size();
  Eigen::VectorXd fd(mf * r.n_solid), fv(mf * r.n_solid);
  for (int j = 0; j < r.n_solid; ++j) {
    fd.segment(j * mf, mf) = map_.to_fluid(d.segment(j * nv, nv));
    fv.segment(j * mf, mf) = map_.to_fluid(v.segment(j * nv, nv));
  }
  const double start = step.t_np1 - r.time.dt;
  FluidLoads loads = fluid_.solve_window(info, Waveform::window(start, r.time.dt, start_d, fd, r.n_solid),
                                         Waveform::window(start, r.time.dt, start_v, fv, r.n_solid), r.n_fluid);
  const Eigen::Index m = mf * r.n_fluid;
  if (loads.traction_samples.size() != m || loads.velocity_integral_samples.size() != m)
    throw Stop{"failed", fmt::format("fluid '{}' returned {} interface samples of its {} substeps, expected {}",
                                     fluid_.name(), loads.traction_samples.size(), r.n_fluid, m)};
  return loads;
}

void Coupler::window_force(const Run& r, const Step& step, Iterate& it, const Eigen::VectorXd& d,
                           const Eigen::VectorXd& v, Eigen::VectorXd& f_star, Eigen::VectorXd& mismatch) const {
  if (r.n_solid == 1 && r.n_fluid == 1) {
    const Eigen::VectorXd fs = map_.to_solid(it.loads.traction_force), fv = map_.to_solid(it.loads.velocity_integral);
    f_star = robin_force(fs, fv, v, d, it.mass);
    mismatch = traction_mismatch(it, fs, fv, d, v, step.force);
    return;
  }
  const Eigen::Index nv = r.nv;
  const double start = step.t_np1 - r.time.dt;
  const Waveform wd = Waveform::window(start, r.time.dt, r.state.d_s_prev, d, r.n_solid);
  const Waveform wv = Waveform::window(start, r.time.dt, r.state.v_s_prev, v, r.n_solid);
  const Waveform ws = Waveform::window(start, r.time.dt, r.state.v_s_prev, velocity_samples(it.s), r.n_solid);
  const Eigen::VectorXd& traction = r.n_fluid == 1 ? it.loads.traction_force : it.loads.traction_samples;
  const Eigen::VectorXd& integral = r.n_fluid == 1 ? it.loads.velocity_integral : it.loads.velocity_integral_samples;
  const Eigen::Index mf = traction.size() / r.n_fluid;
  f_star.resize(nv * r.n_fluid);
  mismatch.resize(nv * r.n_fluid);
  for (int j = 0; j < r.n_fluid; ++j) {
    const double t = substep_time(start, r.time.dt, j + 1, r.n_fluid);
    const Eigen::VectorXd fs = map_.to_solid(traction.segment(j * mf, mf)),
                          fv = map_.to_solid(integral.segment(j * mf, mf));
    const Eigen::VectorXd dj = wd.at(t), vj = wv.at(t);
    Iterate sample;
    sample.mass = it.mass;
    sample.damping = it.damping;
    sample.s.interface_velocity = ws.at(t);
    f_star.segment(j * nv, nv) = robin_force(fs, fv, vj, dj, it.mass);
    mismatch.segment(j * nv, nv) = traction_mismatch(sample, fs, fv, dj, vj, step.force.segment(j * nv, nv));
    if (j + 1 == r.n_fluid) it.traction = sample.traction;
  }
}

std::unique_ptr<Coupler::Scheme> Coupler::make_scheme() {
  if (settings_.scheme == CouplingScheme::Parallel) return std::make_unique<ParallelScheme>(*this);
  if (settings_.scheme == CouplingScheme::RobinNeumann) return std::make_unique<RobinNeumannScheme>(*this);
  return std::make_unique<SerialScheme>(*this);
}

Coupler::Step Coupler::begin_step(Run& r, int n) {
  Step step;
  step.n = n;
  step.t_np1 = n * r.time.dt;
  const State& st = r.state;
  step.force = predict_force(predictor_scheme(settings_.predictor), st.force_history());
  const std::size_t n_measures = settings_.measures.size();
  step.converged = n_measures == 0;
  step.first_r.assign(n_measures, 0.0);
  step.values.assign(n_measures, 0.0);
  r.accelerator->begin_step();
  step.d_iter_prev = repeated(st.d_s_prev, r.n_solid);
  step.v_iter_prev = repeated(st.v_s_prev, r.n_solid);
  r.scheme->begin_step(r, step);
  return step;
}

// The start of a coupling iteration, serial or parallel: a signal stops here; Algorithm 2's
// damping operator of this solve (H^T M_f H of the fluid's last solve, consistent, or the
// solid's own int N^T N) handed to the solid.
Coupler::Update Coupler::begin_iteration(Run& r, const Step& step) {
  if (interrupt_flag())
    throw Stop{"interrupted", fmt::format("interrupted by a signal at step {} iteration {}", step.n, step.k)};
  Update u;
  u.iterate.damping = solid_damping_mass(r.state.mapped_mass);
  if (consistent_damping_ && r.state.mapped_mass.rows() > 0) {
    Timer t(times_.solid);
    solid_.set_interface_mass(u.iterate.damping);
  }
  return u;
}

// The iteration's residual quantities (force change, traction mismatch, displacement and
// velocity change) and their sizes, for the convergence measures and iterations.csv.
void Coupler::measure(Step& step, Update& u, const Eigen::VectorXd& traction_change) const {
  const SolidStepResult& s = u.iterate.s;
  u.norm = u.relaxed.norm();
  u.change = (u.relaxed - step.force).norm();
  step.residual = u.change / std::max(u.norm, settings_.residual_floor);
  // Over the window: the solid's samples (its one step's state without substeps).
  const Eigen::VectorXd &d = displacement_samples(s), &v = velocity_samples(s);
  const double r_quantity[4] = {u.change, traction_change.norm(), (d - step.d_iter_prev).norm(),
                                (v - step.v_iter_prev).norm()};
  const double q_quantity[4] = {u.norm, u.iterate.traction.norm(), d.norm(), v.norm()};
  std::copy(r_quantity, r_quantity + 4, u.r_quantity);
  std::copy(q_quantity, q_quantity + 4, u.q_quantity);
  step.d_iter_prev = d;
  step.v_iter_prev = v;
}

bool Coupler::measures_met(Step& step, const Update& u) const {
  bool all_met = true, any_met = false;
  for (std::size_t i = 0; i < settings_.measures.size(); ++i) {
    const auto& m = settings_.measures[i];
    const int q = static_cast<int>(m.quantity);
    const double r = u.r_quantity[q];
    if (step.k == 1) step.first_r[i] = r;
    step.values[i] = m.type == MeasureType::Absolute   ? r
                     : m.type == MeasureType::Relative ? r / std::max(u.q_quantity[q], settings_.residual_floor)
                     : step.k == 1                     ? 1.0
                                                       : r / std::max(step.first_r[i], settings_.residual_floor);
    const bool met = step.values[i] < m.limit && !(m.type == MeasureType::ResidualRelative && step.k == 1 && r > 0);
    all_met = all_met && met;
    any_met = any_met || met;
  }
  return settings_.combine_all ? all_met : any_met;
}

bool Coupler::finish_iteration(Run& r, Step& step, const Update& u, bool met) {
  const int n = step.n, k = step.k;
  std::vector<double> row_values{double(n),
                                 step.t_np1,
                                 double(k),
                                 step.residual,
                                 u.norm,
                                 double(u.iterate.s.newton_iterations),
                                 double(u.iterate.loads.nonlinear_iterations),
                                 u.r_quantity[1],
                                 u.q_quantity[1],
                                 u.r_quantity[2],
                                 u.q_quantity[2],
                                 u.r_quantity[3],
                                 u.q_quantity[3]};
  row_values.insert(row_values.end(), step.values.begin(), step.values.end());
  row_values.insert(row_values.end(), u.columns.begin(), u.columns.end());
  r.iterations.row(row_values);
  step.last = u.iterate;
  step.last.force_applied = step.force;
  step.force = u.relaxed;
  step.x_d = u.next_d, step.x_v = u.next_v, step.gap = u.gap;  // the parallel scheme's x^(k+1)
  ++r.out.iterations;
  if (u.norm > settings_.force_limit)
    throw Stop{"diverged", fmt::format("interface force norm {:.3e} exceeds force_limit {:.3e} at step {} "
                                       "iteration {} (loosely coupled instability?)",
                                       u.norm, settings_.force_limit, n, k)};
  const double residual = u.watched_residual, change = u.watched_change;
  if (k == 1) step.first_residual = residual, step.first_change = change;
  if (settings_.measures.empty()) return false;
  if (met && r.scheme->converged(u)) return true;
  step.history.push_back(residual);
  // Geometric growth keeps the relative residual constant: watch the absolute change.
  if (k > 1 && (residual > settings_.divergence_factor * std::max(step.first_residual, settings_.residual_floor) ||
                change > settings_.divergence_factor * std::max(step.first_change, settings_.residual_floor)))
    throw Stop{"diverged", fmt::format("coupling residual grew: {} from {:.3e} to {:.3e} "
                                       "(relative {:.3e} to {:.3e}) at step {} iteration {} "
                                       "(relaxation {} above the stability limit?)",
                                       r.scheme->residual_name(), step.first_change, change, step.first_residual,
                                       residual, n, k, settings_.beta)};
  return false;
}

// An unconverged step's last iterations: the residual's rate over the last kWindow of them
// (a stall when it is near 1) and, with Algorithm 2 far above the solid's interface impedance
// (its iterations contract by about 1 - beta (Z_s + Z_f) / (Z_s + gamma_N1)), that ratio. A
// rate is not a forecast: a coupling iteration may crawl for hundreds of iterations and then
// converge, so it is said when the iterations are spent, not used to stop them early.
std::string Coupler::stall_note(const Step& step) const {
  constexpr std::size_t kWindow = 20;
  std::string note;
  const auto& h = step.history;
  if (h.size() > kWindow && h[h.size() - 1 - kWindow] > 0 && h.back() > 0) {
    const double rate = std::pow(h.back() / h[h.size() - 1 - kWindow], 1.0 / kWindow);
    if (rate > 0.95 && rate < 1)
      note = fmt::format(
          "; coupling stalled: the residual fell from {:.3e} to {:.3e} over the last {} iterations "
          "({:.4f} per iteration)",
          h[h.size() - 1 - kWindow], h.back(), kWindow, rate);
    else if (rate >= 1)
      note = fmt::format("; the residual grew over the last {} iterations ({:.4f} per iteration)", kWindow, rate);
  }
  if (impedance_ratio_ > 10)
    note += fmt::format(
        "; Algorithm 2's gamma_N1 is {:.3g} times the solid's interface impedance m_s / |Gamma| / dt: a smaller "
        "gamma_N1 (coupling.robin_auto: solid sets it to the impedance) contracts faster",
        impedance_ratio_);
  return note;
}

void Coupler::check_unconverged(const Step& step) const {
  if (step.converged) return;
  const std::size_t n_measures = settings_.measures.size();
  for (std::size_t i = 0; i < n_measures; ++i) {
    const auto& m = settings_.measures[i];
    if (m.strict && !(step.values[i] < m.limit))
      throw Stop{"diverged", fmt::format("coupling measure {} (strict) not met in {} iterations at step {}: "
                                         "{:.3e} >= {:.1e}",
                                         m.name(), settings_.max_iterations, step.n, step.values[i], m.limit)};
  }
  if (!settings_.stop_if_not_converged) return;
  std::string missed;
  for (std::size_t i = 0; i < n_measures; ++i)
    missed += fmt::format("{}{} {:.3e} (limit {:.1e})", missed.empty() ? "" : ", ", settings_.measures[i].name(),
                          step.values[i], settings_.measures[i].limit);
  throw Stop{"diverged", fmt::format("coupling tolerance not reached in {} iterations at step {}: {} (force residual "
                                     "{:.3e}, first {:.3e}){}",
                                     settings_.max_iterations, step.n, missed, step.residual, step.first_residual,
                                     stall_note(step))};
}

void Coupler::accept_step(Run& r, Step& step) {
  const int n = step.n;
  const double t_np1 = step.t_np1;
  const int used = std::min(step.k, settings_.max_iterations);
  const Iterate& last = step.last;
  r.scheme->accept(r, step);
  // Accept the step on both sides; record probes.
  const StepInfo accepted{t_np1, r.time.dt, n, used};
  std::map<std::string, double> row;
  {
    Timer t(times_.solid);
    for (const auto& [name, v] : solid_.accept_step(accepted)) row["solid." + name] = v;
  }
  {
    Timer t(times_.fluid);
    for (const auto& [name, v] : fluid_.accept_step(accepted)) row["fluid." + name] = v;
  }
  {
    Timer t(times_.coupler);
    interface_balance(r, last, row);
  }
  const State& st = r.state;
  row["coupling.iterations"] = used;
  row["coupling.residual"] = step.residual;
  row["coupling.work_solid"] = st.work_solid;
  row["coupling.work_fluid"] = st.work_fluid;
  row["coupling.work_mapping_error"] = std::abs(st.work_fluid - st.work_fluid_on_solid);
  for (const auto& [name, v] : row)
    if (!std::isfinite(v)) throw Stop{"diverged", fmt::format("probe '{}' is not finite at step {}", name, n)};
  r.probes->add(t_np1, row);
  r.out.steps = n;  // the step is in probes.csv: a later failure (its output) reports it done
  // before the checkpoint of this step, so a checkpoint never has fewer timing rows than steps
  r.timing.row(std::vector<double>{double(n), t_np1, r.wall_before + (now() - r.segment_start), times_.fluid,
                                   times_.solid, double(used)});
  if (r.time.output_every > 0 && n % r.time.output_every == 0)
    write_output(
        r, accepted,
        InterfaceFields{last.s.interface_displacement, last.s.interface_velocity, end_of(last.force_applied, r.nv),
                        map_.to_solid(last.loads.traction_force), map_.to_solid(last.loads.velocity_integral), last.d_f,
                        map_.to_fluid(last.s.interface_velocity), last.loads.traction_force,
                        last.loads.velocity_integral});
  r.accelerator->end_step();
  r.state.accept_force(step.force);
  r.growth.add(last.s.interface_displacement.lpNorm<Eigen::Infinity>(), n, settings_.growth_factor,
               settings_.growth_window);
  // ... and at the final step, so that extending the run (--resume --set time.end) recomputes nothing
  if (r.checkpoints && (n % r.time.checkpoint_every == 0 || n == r.time.steps)) {
    save_checkpoint(r, n, t_np1);
    r.data["checkpoints"]["seconds"] = times_.checkpoint;
  }
  times_.total = now() - r.start;
  if (on_step) on_step(r.out);
  r.progress->update(n, t_np1, fmt::format("iterations {} residual {:.2e}", used, step.residual));
}

void Coupler::interface_balance(Run& r, const Iterate& last, std::map<std::string, double>& row) {
  State& st = r.state;
  const double gamma = r.gamma_n1;
  const SolidStepResult& s = last.s;
  const Eigen::VectorXd applied = end_of(last.force_applied, r.nv);  // at the window's end
  st.work_solid += applied.dot(s.interface_displacement - st.d_s_prev);
  st.work_fluid -= last.loads.traction_force.dot(last.d_f - st.d_f_prev);
  // The same work evaluated on the solid's nodes through the transpose mapping:
  // identical up to round-off (the mapping neither creates nor destroys energy).
  st.work_fluid_on_solid -= map_.to_solid(last.loads.traction_force).dot(s.interface_displacement - st.d_s_prev);
  // The interface power balance of the step (average over dt): the coupling load in the
  // solid's equation (its force and its own Robin damping), the physical traction of the
  // fluid, and the part of the gamma_N1 terms that would remain at exact convergence,
  // gamma (H^T M_f H - C) v_s with both operators in the accepted configuration (zero
  // when the solid's operator is the fluid's, robin_mass: consistent).
  const Eigen::VectorXd dd = s.interface_displacement - st.d_s_prev;
  const Eigen::VectorXd& v = s.interface_velocity;
  Eigen::VectorXd load = applied;
  if (last.damping.rows() > 0) load -= gamma * apply_nodal(last.damping, v);
  double uncancelled = 0;
  const double g = r.implicit ? gamma : settings_.gamma_f;  // the parameter of C's term
  if (g > 0) {
    const NodalMatrix m_phys = physical_mass(s.interface_displacement, last.mass);
    const NodalMatrix c_cfg =
        r.implicit ? solid_damping_mass(last.mass) : algorithm1_mass(s.interface_displacement, last.mass);
    uncancelled = g * (apply_nodal(m_phys, v) - apply_nodal(c_cfg, v)).dot(dd);
  }
  st.work_uncancelled += uncancelled;
  row["coupling.power_solid"] = load.dot(dd) / r.time.dt;
  row["coupling.power_fluid"] = -last.traction.dot(dd) / r.time.dt;
  row["coupling.power_uncancelled"] = uncancelled / r.time.dt;
  row["coupling.work_uncancelled"] = st.work_uncancelled;
  if (r.dim == 2) {
    Eigen::Vector2d total = Eigen::Vector2d::Zero();
    for (Eigen::Index i = 0; i < r.ns; ++i) total -= last.traction.segment<2>(2 * i);
    row["coupling.solid_force_x"] = total(0);
    row["coupling.solid_force_y"] = total(1);
  } else {
    Eigen::Vector3d total = Eigen::Vector3d::Zero();
    for (Eigen::Index i = 0; i < r.ns; ++i) total -= last.traction.segment<3>(3 * i);
    row["coupling.solid_force_x"] = total(0);
    row["coupling.solid_force_y"] = total(1);
    row["coupling.solid_force_z"] = total(2);
  }
  st.d_s_prev = s.interface_displacement;
  st.v_s_prev = s.interface_velocity;
  st.d_f_prev = last.d_f;
}
}  // namespace fsi::coupling
