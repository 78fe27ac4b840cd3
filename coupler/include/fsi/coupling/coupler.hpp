#pragma once
// The coupler's time loop: the seed paper's Algorithms 1 and 2 with the force predictor,
// constant relaxation and a fixed number of iterations or a residual tolerance.
//
// Per step n -> n+1 (F_n = the last relaxed force of step n; F_0 = -F* of the initial state):
//   F^(1) = F_n (predictor)
//   for k = 1..k_max:
//     solid:  M a + [M_fs v] + F_int(d) = F^(k)         ([M_fs v] for Algorithm 2 only)
//     fluid:  mesh <- H d_s, Nitsche velocity <- H v_s  -> f_sigma, f_v (mapped back by H^T)
//     F*  = f_sigma + gamma (M_G v_s - f_v)    (Algorithm 1)
//     F*  = f_sigma - gamma f_v                (Algorithm 2)
//     F^(k+1) = -beta F* + (1 - beta) F^(k)
//   accept both; F_{n+1} = F^(k+1)
// coupling.scheme: parallel (settings.hpp) solves the solid with F^(k) and the fluid with the
// interface state x^(k) = (d^(k), v^(k)) at the same time and relaxes the stacked [d; v; F].
//
// Checkpoints (time.checkpoint_every: N): after every N-th accepted step the coupler saves
// the state of both solvers and its own (F_n, F_{n-1}, the accelerator's reused secant
// pairs, the work accumulators, counters) under OUT/checkpoints/ (checkpoint.hpp); a
// resumed run continues from the newest one and writes the same probes.csv, byte for byte.
//
// Glossary (name -> the paper's symbol -> unit; proto/README.md has the protocol's side):
//   settings_.gamma_n1  gamma_N1  Robin parameter, Algorithm 2's damping   kg/(m^2 s)
//   settings_.gamma_f   gamma_f   the fluid's Nitsche penalty (= gamma_N1)  kg/(m^2 s)
//   settings_.gamma_n2  gamma_N2  Nitsche symmetry switch                   -
//   settings_.beta      beta      relaxation                                -
//   Step::force         F^(k)     nodal force on the solid                  N
//   robin_force()       F*        the algorithm's force from the fluid       N
//   FluidLoads          f_sigma, f_v = int N^T sigma n, int N^T v_f          N, m^3/s
//   mapped_mass         M_G = H^T M_f H, int N^T N on the interface          m^2
//
// The parts: coupler.cpp (the step: run()'s loop, F*, measures, accept), run_setup.cpp
// (configuring, the set-up's report), run_lifecycle.cpp (start state, resume, fork, tables,
// checkpoints) and src/schemes/ (serial, parallel, robin-neumann behind Coupler::Scheme).
//
// Usage: Coupler c(solid, fluid, scene, out_dir); RunOutcome r = c.run();
// The models may be in-process (tests) or remote proxies (protocol/remote.hpp).
#include <Eigen/Core>
#include <atomic>
#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <string>

#include "fsi/common/config.hpp"
#include "fsi/common/run_report.hpp"
#include "fsi/common/solver_model.hpp"
#include "fsi/coupling/interface_map.hpp"
#include "fsi/coupling/settings.hpp"

namespace fsi {
struct TimeSettings;  // fsi/common/standalone.hpp
class StateArchive;   // fsi/common/state.hpp
}  // namespace fsi

namespace fsi::coupling {

struct InterfaceFields;  // fsi/coupling/interface_output.hpp

struct RunOutcome {
  std::string status = "running";  // completed / diverged / failed / interrupted
  std::string reason;
  int steps = 0;
  long iterations = 0;
  int resumed_from = -1;      // the checkpoint's step when resumed
  bool write_failed = false;  // an output file could not be written (a full disk): exit 74
  int exit_code() const {
    if (write_failed) return kExitWriteFailed;
    return status == "completed" ? 0 : status == "diverged" ? 2 : status == "interrupted" ? 130 : 1;
  }
  static constexpr int kExitWriteFailed = 74;  // EX_IOERR (sysexits.h)
};

struct CouplerTimes {
  double total = 0, solid = 0, fluid = 0, coupler = 0;  // wall seconds
  double checkpoint = 0;                                // saving checkpoints (all three parts)
};

class Coupler {
 public:
  Coupler(SolidModel& solid, FluidModel& fluid, const Scene& scene, std::filesystem::path out_dir);
  // Continue from the newest complete checkpoint in OUT/checkpoints (resume), refusing when
  // the scene's parameters differ; with `allow_fresh_start`, a folder without one starts at
  // step 0 instead of failing (automatic recovery before the first checkpoint).
  void set_resume(bool resume, bool allow_fresh_start = false) {
    resume_ = resume;
    allow_fresh_start_ = allow_fresh_start;
  }
  // Runs the whole scene. Never throws for a run-time failure: the outcome says why.
  // Writes probes.csv and iterations.csv row by row; fills `report` (summary.json).
  RunOutcome run(RunReport& report);
  const CouplerTimes& times() const { return times_; }
  // Set from a signal handler to stop between iterations.
  static std::atomic<bool>& interrupt_flag();
  // Called after each accepted step (for progress/summary refresh by the app).
  std::function<void(const RunOutcome&)> on_step;

 private:
  // F* of the algorithm from the mapped loads; `mapped_mass` = H^T M_f H of the same fluid
  // solve (empty when the fluid does not send M_f).
  Eigen::VectorXd robin_force(const Eigen::VectorXd& traction, const Eigen::VectorXd& velocity_integral,
                              const Eigen::VectorXd& solid_velocity, const Eigen::VectorXd& solid_displacement,
                              const NodalMatrix& mapped_mass) const;
  // Algorithm 1's M_G in F* (robin_mass: consistent = mapped_mass; solid = the polyline mass
  // in the current configuration).
  NodalMatrix algorithm1_mass(const Eigen::VectorXd& solid_displacement, const NodalMatrix& mapped_mass) const;
  // The solid's damping operator C (Algorithm 2 with gamma_N1 > 0; else empty): mapped_mass
  // when the solid takes it, else the solid's own reference int N^T N.
  NodalMatrix solid_damping_mass(const NodalMatrix& mapped_mass) const;
  // The operator of the fluid's penalty term seen from the solid: mapped_mass, or without one
  // (a fluid that does not send M_f) the solid's polyline mass in the current configuration.
  NodalMatrix physical_mass(const Eigen::VectorXd& solid_displacement, const NodalMatrix& mapped_mass) const;
  // The parts of run(), in the order it calls them (types defined in coupler.cpp).
  struct Run;      // one run: its settings, outputs, tables, checkpoints, accelerator and State
  struct State;    // what carries from one accepted step to the next (and into a checkpoint)
  struct Iterate;  // one coupling iteration's solves; a step accepts its last one
  struct Step;     // the step being iterated: F^(k), the residuals, the measures
  struct Update;   // what one coupling iteration gives: F^(k+1) and the residual quantities
  struct Scheme;   // coupling.scheme: the iteration's solves, behind one interface (src/schemes/)
  struct SerialScheme;
  struct ParallelScheme;
  struct RobinNeumannScheme;
  std::unique_ptr<Scheme> make_scheme();
  // 1. The scene's time and coupling sections; both solvers configured, the interface map.
  TimeSettings configure(InterfaceMeshData& fluid_interface);
  void automatic_robin(const TimeSettings& time);  // coupling.robin_auto: gamma from the solid's mass
  // summary.json's "interface" and "coupling", and the set-up's log lines and warnings.
  void describe_setup(nlohmann::json& data, const TimeSettings& time, const InterfaceMeshData& fluid_interface);
  void check_gap(nlohmann::json& data, const InterfaceMeshData& fluid_interface) const;
  std::string stall_note(const Step& step) const;  // check_unconverged's rate and impedance note
  // 2. The state the first step starts from: a checkpoint (resume, fork) or the initial one.
  void start_state(Run& r);
  void find_restart(Run& r);  // --resume's checkpoint, forked_from.json
  void load_restart(Run& r);  // both solvers' and the coupler's parts
  void read_coupler_state(Run& r, const StateArchive& c);
  void convert_forked_predictor(Run& r, const StateArchive& c);  // forked into another algorithm / gamma_N1
  void initial_state(Run& r);                                    // F_0 = -F*(initial fluid state)
  // probes.csv, iterations.csv and timing.csv: new, or continued after the checkpoint.
  void open_tables(Run& r);
  // 3. One step: its iterations, then accept.
  Step begin_step(Run& r, int n);
  Update begin_iteration(Run& r, const Step& step);  // signal check, Algorithm 2's damping to the solid
  Eigen::VectorXd traction_mismatch(Iterate& it, const Eigen::VectorXd& fs, const Eigen::VectorXd& fv,
                                    const Eigen::VectorXd& d, const Eigen::VectorXd& v,
                                    const Eigen::VectorXd& force) const;              // H^T R into it, and its mismatch
  void measure(Step& step, Update& u, const Eigen::VectorXd& traction_change) const;  // residual quantities
  bool measures_met(Step& step, const Update& u) const;                               // the convergence measures
  // The iteration's row in iterations.csv, F^(k+1); throws on divergence; true when converged.
  bool finish_iteration(Run& r, Step& step, const Update& u, bool met);
  void check_unconverged(const Step& step) const;  // strict measures, stop_if_not_converged
  void accept_step(Run& r, Step& step);            // accept calls, probes, output, checkpoint
  void interface_balance(Run& r, const Iterate& last, std::map<std::string, double>& row);
  void save_checkpoint(Run& r, int n, double t_np1);
  // H^T M_f H of a fluid solve (empty when the fluid does not send M_f).
  NodalMatrix map_mass(Run& r, const FluidLoads& loads);
  // Waveform iterations (solid.substeps, fluid.substeps): the solid's solve of the window with
  // F^(k) (the fluid's samples); the fluid's with the solid-side interface state (the solid's
  // samples), it.d_f its end mapped; F* and the traction mismatch sample by sample at the
  // fluid's substep times (the solid's state interpolated there). With one substep each, the
  // solves and formulas of a step without waveforms.
  SolidStepResult solve_solid(const Run& r, const Step& step, const StepInfo& info, const Eigen::VectorXd& force);
  FluidLoads solve_fluid(const Run& r, const Step& step, const StepInfo& info, const Eigen::VectorXd& d,
                         const Eigen::VectorXd& v, Eigen::VectorXd& d_f);
  void window_force(const Run& r, const Step& step, Iterate& it, const Eigen::VectorXd& d, const Eigen::VectorXd& v,
                    Eigen::VectorXd& f_star, Eigen::VectorXd& mismatch) const;
  void write_output(Run& r, const StepInfo& info, const InterfaceFields& fields);

  int solid_substeps_ = 1, fluid_substeps_ = 1;  // solid.substeps, fluid.substeps
  bool consistent_damping_ = false;              // Algorithm 2 and the solid takes H^T M_f H
  double impedance_ratio_ = 0;                   // Algorithm 2: gamma_N1 / (m_s / |Gamma| / dt); 0 = unknown
  double robin_auto_value_ = 0;                  // coupling.robin_auto's (m_s / |Gamma|) / dt
  SolidModel& solid_;
  FluidModel& fluid_;
  const Scene& scene_;
  std::filesystem::path out_dir_;
  CouplingSettings settings_;
  InterfaceMeshData solid_interface_;
  InterfaceMap map_;
  CouplerTimes times_;
  bool resume_ = false;
  bool allow_fresh_start_ = false;
};

}  // namespace fsi::coupling
