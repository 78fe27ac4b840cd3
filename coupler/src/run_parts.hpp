#pragma once
// The coupler's run, in parts (internal to fsi_coupling): the helpers every part uses, and the
// types of coupler.hpp's private declarations. Three files define Coupler's members:
//   coupler.cpp        the step: run()'s loop, the Robin force, the iterations, convergence, accept
//   run_setup.cpp      configuring both solvers and the map, the set-up's report
//   run_lifecycle.cpp  the state a run starts from (initial, resume, fork), tables, checkpoints
// and src/schemes/ the coupling schemes (serial, parallel) behind Coupler::Scheme.
#include <fmt/format.h>

#include <Eigen/Core>
#include <algorithm>
#include <chrono>
#include <deque>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "fsi/common/log.hpp"
#include "fsi/common/standalone.hpp"
#include "fsi/common/state.hpp"
#include "fsi/common/table_writer.hpp"
#include "fsi/coupling/acceleration.hpp"
#include "fsi/coupling/checkpoint.hpp"
#include "fsi/coupling/coupler.hpp"
#include "fsi/coupling/interface_output.hpp"

namespace fsi::coupling {
namespace run_detail {

inline double now() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

// Adds wall time of a scope to an accumulator.
class Timer {
 public:
  explicit Timer(double& acc) : acc_(acc), start_(now()) {}
  ~Timer() { acc_ += now() - start_; }

 private:
  double& acc_;
  double start_;
};

inline bool all_finite(const Eigen::VectorXd& v) { return v.allFinite(); }

// Waveforms: `count` copies of v, concatenated (v itself for one).
inline Eigen::VectorXd repeated(const Eigen::VectorXd& v, int count) {
  if (count == 1) return v;
  Eigen::VectorXd out(v.size() * count);
  for (int j = 0; j < count; ++j) out.segment(j * v.size(), v.size()) = v;
  return out;
}
// The last of a waveform's samples of m values each: the window's end.
inline Eigen::VectorXd end_of(const Eigen::VectorXd& samples, Eigen::Index m) {
  return samples.size() == m ? samples : Eigen::VectorXd(samples.tail(m));
}
// The solid's interface state over the window: its samples, or its one step's.
inline const Eigen::VectorXd& displacement_samples(const SolidStepResult& s) {
  return s.displacement_samples.size() > 0 ? s.displacement_samples : s.interface_displacement;
}
inline const Eigen::VectorXd& velocity_samples(const SolidStepResult& s) {
  return s.velocity_samples.size() > 0 ? s.velocity_samples : s.interface_velocity;
}

// A run-time stop with its classification.
struct Stop {
  std::string status, reason;
};

// coupling.growth: the largest interface displacement |d|_inf of the last `window` accepted
// steps against that of the `window` steps before; more than `factor` times = unbounded growth
// (a loosely coupled scheme above its stability limit), the run diverged. Watched from step
// 2 x window of this segment on (a resumed run starts watching again).
class GrowthWatch {
 public:
  void add(double value, int step, double factor, int window) {
    const auto w = static_cast<std::size_t>(window);
    history_.push_back(value);
    if (history_.size() > 2 * w) history_.pop_front();
    if (history_.size() < 2 * w) return;
    const double before = *std::max_element(history_.begin(), history_.begin() + static_cast<std::ptrdiff_t>(w));
    const double last = *std::max_element(history_.begin() + static_cast<std::ptrdiff_t>(w), history_.end());
    if (before > 0 && last > factor * before)  // growth from exactly 0 (a load that starts late) is not measured
      throw Stop{"diverged",
                 fmt::format("unbounded growth: the interface displacement grew {:.3g}-fold in {} steps (largest "
                             "|d| {:.3e} in steps {}-{}, {:.3e} in steps {}-{}; coupling.growth.factor {:g}): a "
                             "loosely coupled scheme above its stability limit?",
                             last / before, window, before, step - 2 * window + 1, step - window, last,
                             step - window + 1, step, factor)};
  }

 private:
  std::deque<double> history_;
};

}  // namespace run_detail

// ---------------------------------------------------------------------------------------
// The run's parts. run() reads as: configure, describe, start state, open tables, then per
// step: begin, coupling iterations until converged, accept.

// What carries from one accepted step to the next, and what a checkpoint saves of the
// coupler (with the accelerator's reused secant pairs and the iteration count).
struct Coupler::State {
  // The accepted forces for the predictor: F_n, F_{n-1}, F_{n-2}, F_{n-3}, of which the first
  // `forces_known` are (F_0 = -F* of the initial state; the others copies of the oldest).
  Eigen::VectorXd force_n, force_nm1, force_nm2, force_nm3;
  int forces_known = 1;
  std::vector<Eigen::VectorXd> force_history() const {
    const std::vector<Eigen::VectorXd> all{force_n, force_nm1, force_nm2, force_nm3};
    return std::vector<Eigen::VectorXd>(all.begin(), all.begin() + std::clamp(forces_known, 1, 4));
  }
  void accept_force(const Eigen::VectorXd& f) {
    force_nm3 = force_nm2;
    force_nm2 = force_nm1;
    force_nm1 = force_n;
    force_n = f;
    forces_known = std::min(forces_known + 1, 4);
  }
  // The accepted interface state: the solid's displacement and velocity (the velocity
  // measure's k = 1 reference), the fluid's displacement.
  Eigen::VectorXd d_s_prev, v_s_prev, d_f_prev;
  // Work done across the interface, on each side: by the load the solid was actually
  // given, and by the fluid's traction on the fluid's interface motion. With the
  // transpose mapping they differ only by the partitioned scheme's lag and relaxation.
  double work_solid = 0, work_fluid = 0, work_fluid_on_solid = 0, work_uncancelled = 0;
  // M_G = H^T M_f H of the fluid's last solve (empty when the fluid does not send M_f).
  NodalMatrix mapped_mass;
  // Its entries of the coupler's checkpoint part (run_lifecycle.cpp). load() checks the sizes
  // (nv values per vector, ns nodes of mapped_mass) and says whether mapped_mass was there
  // (checkpoints of earlier versions hold none).
  void save(StateArchive& c) const;
  // (nf values per force: F is the fluid's samples over the window). `fork`: a checkpoint whose
  // forces hold another number of samples per window (another fluid.substeps) is resampled
  // (resample_forces); `resampled` says whether it was.
  bool load(const StateArchive& c, Eigen::Index nv, Eigen::Index nf, Eigen::Index ns, const std::string& dir,
            bool fork = false, bool* resampled = nullptr);
  // The force histories of k samples per window as nf / nv samples: piecewise linear in time
  // through the windows' end values (each force's last sample), constant before the oldest.
  void resample_forces(Eigen::Index nv, Eigen::Index nf);
};

// One coupling iteration's solves; the step accepts its last one.
struct Coupler::Iterate {
  Eigen::VectorXd force_applied;  // F^(k), the solid's load
  SolidStepResult s;
  FluidLoads loads;
  Eigen::VectorXd d_f;       // the fluid's interface displacement H d_s
  Eigen::VectorXd traction;  // the physical traction H^T R (without the fluid's penalty part)
  NodalMatrix damping;       // Algorithm 2's damping operator of the solid solve (else empty)
  NodalMatrix mass;          // H^T M_f H of the fluid solve
};

// The step n -> n+1 being iterated.
struct Coupler::Step {
  int n = 0;
  double t_np1 = 0;
  int k = 1;              // the coupling iteration; k_max + 1 after k_max unconverged ones
  Eigen::VectorXd force;  // F^(k)
  double first_residual = 0, residual = 0, first_change = 0;
  bool converged = false;
  std::vector<double> first_r, values;       // the measures' k = 1 quantities and their values
  Eigen::VectorXd d_iter_prev, v_iter_prev;  // the last iteration's solid interface state
  Eigen::VectorXd x_d, x_v;                  // parallel: the interface state x^(k) the fluid is given
  double gap = 0;                            // parallel: |d^(k+1) - d^(k)| / |d^(k+1)| of the last update
  std::vector<double> history;               // the residual of every iteration (stall detection)
  Iterate last;
};

// What one coupling iteration gives.
struct Coupler::Update {
  Iterate iterate;
  Eigen::VectorXd relaxed;                          // F^(k+1)
  Eigen::VectorXd next_d, next_v;                   // parallel: x^(k+1)
  double gap = 0;                                   // parallel: |d^(k+1) - d^(k)| / |d^(k+1)|
  double stacked_change = 0, stacked_residual = 0;  // parallel: |x^(k+1) - x^(k)| scaled, and over |x^(k+1)|
  double norm = 0, change = 0;
  // What the divergence test watches (the scheme's residual and change), and the scheme's own
  // iterations.csv columns (Scheme::columns()).
  double watched_residual = 0, watched_change = 0;
  std::vector<double> columns;
  // The interface quantities' changes and sizes: force, traction, displacement, velocity
  // (iterations.csv, convergence measures).
  double r_quantity[4] = {0, 0, 0, 0}, q_quantity[4] = {0, 0, 0, 0};
};

// One run: what it was configured with, its outputs and tables, checkpoints and State.
struct Coupler::Run {
  Run(const Coupler& c, const TimeSettings& time_settings, const InterfaceMeshData& fluid_interface,
      RunOutcome& outcome, nlohmann::json& report_data, double start_time)
      : out(outcome),
        data(report_data),
        log(logger("coupler")),
        time(time_settings),
        gamma_n1(c.settings_.gamma_n1),
        implicit(c.settings_.algorithm == Algorithm::ImplicitSolidVelocity),
        ns(static_cast<Eigen::Index>(c.solid_interface_.nodes())),
        dim(c.solid_interface_.dimension),
        nv(static_cast<Eigen::Index>(c.solid_interface_.values())),
        n_solid(c.solid_substeps_),
        n_fluid(c.fluid_substeps_),
        vtk_dir(c.out_dir_ / "vtk"),
        checkpoints(time.checkpoint_every > 0),
        start(start_time),
        accelerator(make_accelerator(c.settings_)),
        parameters(scene_to_json(c.scene_)),
        store(c.out_dir_ / "checkpoints", time.checkpoint_keep) {
    // Output: both solvers' VTK and the coupling interfaces, every time.output_every steps
    // and at t = 0.
    if (time.output_every > 0) interface_output.emplace(vtk_dir, c.solid_interface_, fluid_interface, time.vtk_format);
    const InterfaceMeshData& si = c.solid_interface_;
    const Eigen::VectorXd d_s =
        si.initial_displacement.size() == nv ? si.initial_displacement : Eigen::VectorXd::Zero(nv);
    const Eigen::VectorXd v_s = si.initial_velocity.size() == nv ? si.initial_velocity : Eigen::VectorXd::Zero(nv);
    state.v_s_prev = v_s;
    state.d_s_prev = d_s;
    state.d_f_prev = c.map_.to_fluid(d_s);
  }
  RunOutcome& out;
  nlohmann::json& data;
  std::shared_ptr<spdlog::logger> log;
  const TimeSettings time;
  const double gamma_n1;
  const bool implicit;
  const Eigen::Index ns;  // solid interface nodes
  const int dim;          // values per interface node (2 or 3)
  const Eigen::Index nv;  // values of a solid interface vector, dim * ns
  // Waveform iterations: the solid's and the fluid's substeps in a window (time.dt). F^(k) is
  // the fluid's samples (n_fluid x nv values), the solid's interface state its samples
  // (n_solid x nv); one each = a step without waveforms.
  const int n_solid, n_fluid;
  const std::filesystem::path vtk_dir;
  const bool checkpoints;
  const double start;  // wall clock at run()'s start
  State state;
  std::unique_ptr<Accelerator> accelerator;
  bool warned_no_fluid_mass = false;
  // Output; a side that answers three requests without writing a file is named once (its
  // section turns output off, or it cannot write any).
  std::optional<InterfaceOutput> interface_output;
  int output_requests = 0;
  std::map<std::string, std::size_t> files_written{{"solid", 0}, {"fluid", 0}};
  // Checkpoints, resume, fork.
  const nlohmann::json parameters;
  CheckpointStore store;
  std::optional<CheckpointStore::Loaded> restart;
  nlohmann::json fork;
  int fork_step = 0;
  long fork_iterations = 0;
  bool at_fork = false;
  double wall_before = 0;    // wall seconds of the run's earlier segments (resumed runs)
  double segment_start = 0;  // wall clock when this segment's first step began
  // Tables.
  std::optional<ProbeTable> probes;
  CsvWriter iterations, timing;
  std::optional<Progress> progress;
  run_detail::GrowthWatch growth;
  std::unique_ptr<Scheme> scheme;  // set by run() before the start state is loaded
};

// A coupling scheme (coupling.scheme): the order of the solves in an iteration and what the
// accelerator acts on. All that differs between schemes is here, behind this interface; the
// step around it (predictor, measures, divergence, accept, checkpoints) is the same for all.
struct Coupler::Scheme {
  explicit Scheme(Coupler& coupler) : c(coupler) {}
  virtual ~Scheme() = default;
  virtual const char* name() const = 0;
  // The name of the residual whose growth the divergence test watches, for its message.
  virtual const char* residual_name() const = 0;
  // iterations.csv's columns of the scheme (after the measures'): Update::columns' names.
  virtual std::vector<std::string> columns() const { return {}; }
  // Before the start state: what the scheme needs of the solvers, checked; its summary entries.
  virtual void prepare(Run& /*r*/) {}
  // The fluid's loads of the initial state (a run that does not start from a checkpoint).
  virtual void initial_loads(const Run& /*r*/, const FluidLoads& /*loads*/) {}
  // A step is accepted (before the State moves on: r.state holds step n, step.last step n+1).
  virtual void accept(const Run& /*r*/, const Step& /*step*/) {}
  // The step's first interface state, where the scheme needs one.
  virtual void begin_step(const Run& r, Step& step) const {}
  // One coupling iteration: the solves, F*, the accelerator's update, the residual quantities
  // (Coupler::measure), Update::watched_* and Update::columns.
  virtual Update iterate(Run& r, Step& step) = 0;
  // Convergence beyond the measures (they are met when this is asked).
  virtual bool converged(const Update& u) const { return true; }
  // What carries over from one step to the next, in the coupler's checkpoint part.
  virtual void save(StateArchive& a) const {}
  virtual void load(const StateArchive& a) {}
  // Does a checkpoint hold what load() reads? A fork from another scheme's checkpoint that does
  // not starts the scheme's history from the checkpoint's state, as initial_loads() from rest.
  virtual bool has_history(const StateArchive& /*a*/) const { return true; }

 protected:
  Coupler& c;
};

struct Coupler::SerialScheme : Coupler::Scheme {
  using Scheme::Scheme;
  const char* name() const override { return "serial"; }
  const char* residual_name() const override { return "|F^(k+1) - F^(k)|"; }
  Update iterate(Run& r, Step& step) override;
};

struct Coupler::RobinNeumannScheme : Coupler::Scheme {
  using Scheme::Scheme;
  const char* name() const override { return "robin-neumann"; }
  const char* residual_name() const override { return "none (explicit)"; }
  std::vector<std::string> columns() const override { return {"kinematic_gap"}; }
  void prepare(Run& r) override;
  void initial_loads(const Run& r, const FluidLoads& loads) override;
  Update iterate(Run& r, Step& step) override;
  void accept(const Run& r, const Step& step) override;
  void save(StateArchive& a) const override;
  void load(const StateArchive& a) override;
  bool has_history(const StateArchive& a) const override;

 private:
  Eigen::VectorXd coefficient_;    // the Robin coefficient per fluid interface node (m_s / |Gamma| / dt)
  Eigen::VectorXd f_n_, f_nm1_;    // the fluid's accepted interface traction forces (fluid nodes)
  Eigen::VectorXd v_nm1_, v_nm2_;  // the solid's accepted interface velocities before v_n
  Eigen::Index fluid_values_ = 0;  // values of a fluid interface vector
};

struct Coupler::ParallelScheme : Coupler::Scheme {
  using Scheme::Scheme;
  const char* name() const override { return "parallel"; }
  const char* residual_name() const override { return "|x^(k+1) - x^(k)| (scaled [d; v; F])"; }
  std::vector<std::string> columns() const override;
  void begin_step(const Run& r, Step& step) const override;
  Update iterate(Run& r, Step& step) override;
  bool converged(const Update& u) const override;
  void save(StateArchive& a) const override;
  void load(const StateArchive& a) override;

 private:
  void stacked_update(Run& r, const Step& step, Update& u, const Eigen::VectorXd& r_force);
  // The block scales of [d; v; F] (0 = not yet set), and the largest each has had: a scale
  // never drops below kScaleFloor times it.
  double scale_[3] = {0, 0, 0};
  double peak_[3] = {0, 0, 0};
};

}  // namespace fsi::coupling
