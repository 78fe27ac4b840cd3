#include "fsi/coupling/coupler.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <deque>
#include <fstream>
#include <future>
#include <limits>
#include <optional>
#include <tuple>

#include "fsi/common/interface_geometry.hpp"
#include "fsi/common/log.hpp"
#include "fsi/common/standalone.hpp"
#include "fsi/common/state.hpp"
#include "fsi/common/table_writer.hpp"
#include "fsi/common/write_check.hpp"
#include "fsi/coupling/acceleration.hpp"
#include "fsi/coupling/checkpoint.hpp"
#include "fsi/coupling/interface_output.hpp"
#include "fsi/coupling/predictor.hpp"

namespace fsi::coupling {
namespace {

double now() { return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count(); }

// Adds wall time of a scope to an accumulator.
class Timer {
 public:
  explicit Timer(double& acc) : acc_(acc), start_(now()) {}
  ~Timer() { acc_ += now() - start_; }

 private:
  double& acc_;
  double start_;
};

bool all_finite(const Eigen::VectorXd& v) { return v.allFinite(); }

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

}  // namespace

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
  const double gamma = settings_.nitsche_penalty, gamma_f = settings_.fluid_penalty;
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
  if (settings_.algorithm != Algorithm::ImplicitSolidVelocity || settings_.nitsche_penalty == 0) return NodalMatrix();
  if (consistent_damping_ && mapped_mass.rows() > 0) return mapped_mass;
  return nodal_interface_mass(solid_interface_, Eigen::VectorXd());  // the solid's own, reference configuration
}

NodalMatrix Coupler::physical_mass(const Eigen::VectorXd& solid_displacement, const NodalMatrix& mapped_mass) const {
  if (mapped_mass.rows() > 0) return mapped_mass;
  return nodal_interface_mass(solid_interface_, solid_displacement);  // a fluid without M_f: the solid's polyline
}

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
  // The parallel scheme's block scales of [d; v; F] (0 = not yet set), and the largest each
  // has had: a scale never drops below kScaleFloor times it.
  double scale[3] = {0, 0, 0};
  double peak[3] = {0, 0, 0};
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
        gamma(c.settings_.nitsche_penalty),
        implicit(c.settings_.algorithm == Algorithm::ImplicitSolidVelocity),
        ns(static_cast<Eigen::Index>(c.solid_interface_.nodes())),
        dim(c.solid_interface_.dimension),
        nv(static_cast<Eigen::Index>(c.solid_interface_.values())),
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
  const double gamma;
  const bool implicit;
  const Eigen::Index ns;  // solid interface nodes
  const int dim;          // values per interface node (2 or 3)
  const Eigen::Index nv;  // values of a solid interface vector, dim * ns
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
  GrowthWatch growth;
};

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
    start_state(r);
    // 3. Time loop.
    open_tables(r);
    phase = Phase::Stepping;
    for (int n = out.steps + 1; n <= time.steps; ++n) {
      Step step = begin_step(r, n);
      for (; step.k <= settings_.max_iterations; ++step.k) {
        const Update u = coupling_iteration(r, step);
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

TimeSettings Coupler::configure(InterfaceMeshData& fluid_interface) {
  auto log = logger("coupler");
  scene_.name();
  schema::require_valid(scene_, {"time", "coupling"});  // every key, before anything is configured
  const TimeSettings time = read_time(scene_);
  settings_ = read_coupling(scene_.section("coupling"));
  scene_.check_all_used("coupling");
  scene_.check_all_used("time");
  for (const auto& key : scene_.root().keys())
    if (key != "scene" && key != "description" && key != "time" && key != "coupling" && key != "solid" &&
        key != "fluid")
      throw ConfigError(
          fmt::format("{}: unknown top-level section '{}' (known: scene, description, time, "
                      "coupling, solid, fluid)",
                      scene_.root().where(key), key));
  if (settings_.predictor != "previous")
    log->warn(
        "predictor '{}' ({}) can excite interface modes the iterations leave unconverged (docs/fsi.md); "
        "'previous' is the paper's and the robust choice",
        settings_.predictor, predictor_scheme(settings_.predictor).phrase);
  if (settings_.robin_auto != RobinAuto::None) automatic_robin(time);
  const double gamma = settings_.nitsche_penalty;
  const bool implicit = settings_.algorithm == Algorithm::ImplicitSolidVelocity;
  if (implicit && gamma > 0 && !solid_.supports_interface_damping())
    throw Stop{"failed",
               fmt::format("Algorithm 2 needs interface damping, which solid '{}' does not support", solid_.name())};
  const auto vtk_dir = out_dir_ / "vtk";
  {
    Timer t(times_.solid);
    solid_.configure(scene_.section("solid"),
                     SolidSetup{time.dt, time.end, implicit ? gamma : 0.0,
                                time.output_every > 0 ? vtk_dir : std::filesystem::path(), time.vtk_format});
  }
  {
    Timer t(times_.fluid);
    fluid_.configure(scene_.section("fluid"),
                     FluidSetup{time.dt, time.end, settings_.fluid_penalty, settings_.nitsche_symmetry,
                                time.output_every > 0 ? vtk_dir : std::filesystem::path(), time.vtk_format});
  }
  solid_interface_ = solid_.interface();
  fluid_interface = fluid_.interface();
  {
    Timer t(times_.coupler);
    try {
      map_ = InterfaceMap(solid_interface_, fluid_interface, settings_.mapping);
    } catch (const std::invalid_argument& e) {
      throw Stop{"failed", fmt::format("solid '{}' and fluid '{}': {}", solid_.name(), fluid_.name(), e.what())};
    }
  }
  return time;
}

// coupling.robin_auto: the solid configured once without damping to report its mass per
// interface measure; gamma_auto = (m_s / |Gamma|) / dt replaces gamma_N1, gamma_f or both.
void Coupler::automatic_robin(const TimeSettings& time) {
  {
    Timer t(times_.solid);
    solid_.configure(scene_.section("solid"), SolidSetup{time.dt, time.end, 0.0, {}});
  }
  const double mass_per_area = solid_.interface().mass_per_area;
  if (!(mass_per_area > 0))
    throw Stop{"failed", fmt::format("coupling.robin_auto needs the solid's mass per interface measure, which "
                                     "solid '{}' does not report (InterfaceMesh.mass_per_area)",
                                     solid_.name())};
  robin_auto_value_ = mass_per_area / time.dt;
  if (settings_.robin_auto != RobinAuto::Fluid) settings_.nitsche_penalty = robin_auto_value_;
  if (settings_.robin_auto != RobinAuto::Solid) settings_.fluid_penalty = robin_auto_value_;
  if (settings_.nitsche_penalty > 0 && settings_.fluid_penalty == 0)
    throw Stop{"failed",
               "coupling.robin_auto: solid sets gamma_N1 > 0 with a fluid penalty of 0: give "
               "coupling.fluid_penalty, or robin_auto: both"};
  logger("coupler")->info(
      "automatic Robin parameter: m_s / |Gamma| = {:.6g}, over dt = {:.6g}: gamma_N1 = {:.6g}, "
      "gamma_f = {:.6g}",
      mass_per_area, time.dt, settings_.nitsche_penalty, settings_.fluid_penalty);
}

// The gap between the two interfaces against the solid's median element size: meshes in
// different frames, units or places map every fluid node onto the solid's nearest edge and run
// on without an error, so a large gap is refused (coupling.interface_gap).
void Coupler::check_gap(nlohmann::json& data, const InterfaceMeshData& fluid_interface) const {
  const auto& solid = solid_interface_;
  std::vector<double> sizes;
  const Eigen::MatrixXd& x = solid.coordinates;
  for (const auto& s : solid.segments) sizes.push_back((x.row(s[1]) - x.row(s[0])).norm());
  for (const auto& f : solid.faces) sizes.push_back(std::sqrt(face_area(x, f)));
  // A point interface: no element size to measure the gap against; a one-node fluid (a model
  // such as the surrogate, which pushes wherever the solid is) has no place to be off.
  if (sizes.empty() || fluid_interface.nodes() == 1) return;
  std::nth_element(sizes.begin(), sizes.begin() + static_cast<std::ptrdiff_t>(sizes.size() / 2), sizes.end());
  const double h = sizes[sizes.size() / 2];
  const double ratio = h > 0 ? map_.max_gap() / h : 0;
  data["interface"]["element_size"] = h;
  data["interface"]["gap_ratio"] = ratio;
  if (ratio <= settings_.gap_warn) return;
  const std::string what = fmt::format(
      "the fluid's interface lies up to {:.3g} m from the solid's ({:.0f} % of the solid interface's median element "
      "size {:.3g} m): are the two meshes in the same frame and units, and is the solid where the fluid's mesh "
      "expects it (its origin)?",
      map_.max_gap(), 100 * ratio, h);
  if (settings_.gap_refuse > 0 && ratio > settings_.gap_refuse)
    throw Stop{"failed", what + fmt::format(" Refused above {:.0f} % (coupling.interface_gap.refuse)",
                                            100 * settings_.gap_refuse)};
  logger("coupler")->warn("{} (warned above {:.0f} %: coupling.interface_gap.warn)", what, 100 * settings_.gap_warn);
}

void Coupler::describe_setup(nlohmann::json& data, const TimeSettings& time, const InterfaceMeshData& fluid_interface) {
  auto log = logger("coupler");
  const double gamma = settings_.nitsche_penalty;
  const bool implicit = settings_.algorithm == Algorithm::ImplicitSolidVelocity;
  const Eigen::Index ns = static_cast<Eigen::Index>(solid_interface_.nodes());
  if (time.output_every > 0)
    for (const auto& [side, ok, who] : {std::tuple{"solid", solid_.supports_output(), solid_.name()},
                                        std::tuple{"fluid", fluid_.supports_output(), fluid_.name()}})
      if (!ok) log->warn("time.output_every: the {} '{}' cannot write output (supports_output is false)", side, who);
  // Point interfaces: both sides' measures (int N^T N) should agree, or the Robin terms
  // weigh the two sides differently (in effect a damping of the wrong size or sign).
  if (solid_interface_.points_only() && fluid_interface.points_only() &&
      solid_interface_.lumped_measure.size() == fluid_interface.lumped_measure.size()) {
    const double a = solid_interface_.lumped_measure.sum(), b = fluid_interface.lumped_measure.sum();
    if (std::abs(a - b) > 1e-9 * std::max(std::abs(a), std::abs(b)))
      log->warn("interface measures differ: solid {} vs fluid {} (interface_measure of the two sections)", a, b);
  }
  data["interface"] = {{"solid_nodes", ns},
                       {"fluid_nodes", fluid_interface.nodes()},
                       {"max_gap", map_.max_gap()},
                       {"conforming", map_.conforming()},
                       {"coincident_nodes", map_.coincident_nodes()},
                       {"mapping", to_string(map_.kind())}};
  if (map_.kind() != MappingKind::NearestSegment) {
    data["interface"]["rbf"] = {{"support_radius", map_.support_radius()},
                                {"linear_terms", map_.linear_terms()},
                                {"condition", map_.condition_estimate()}};
    log->info("mapping {}: RBF on the {} solid interface nodes, {} linear terms{}, condition estimate {:.3g}",
              to_string(map_.kind()), ns, map_.linear_terms(),
              map_.support_radius() > 0 ? fmt::format(", support radius {:.4g} m", map_.support_radius()) : "",
              map_.condition_estimate());
  }
  check_gap(data, fluid_interface);
  if (map_.conforming()) {
    data["interface"]["permutation_error"] = map_.permutation_error();
    log->info(
        "conforming interface: the {} fluid nodes are the solid's (max gap {:.3g} m), H is a permutation "
        "(max |H - P| {:.3g})",
        fluid_interface.nodes(), map_.max_gap(), map_.permutation_error());
  } else {
    log->info(
        "non-conforming interface: {} of the {} fluid nodes coincide with one of the {} solid nodes "
        "(within {:.3g} m), max gap to the solid's interface {:.3g} m: H interpolates",
        map_.coincident_nodes(), fluid_interface.nodes(), ns, map_.coincidence_tolerance(), map_.max_gap());
  }
  // Algorithm 2 far above the solid's interface impedance Z_s = m_s / |Gamma| / dt: converged
  // iterations contract by about 1 - beta (Z_s + Z_f) / (Z_s + gamma_N1), so their number
  // grows like gamma_N1 / Z_s.
  impedance_ratio_ = 0;
  if (implicit && gamma > 0 && solid_interface_.mass_per_area > 0) {
    const double z_s = solid_interface_.mass_per_area / time.dt;
    impedance_ratio_ = gamma / z_s;
    data["coupling_estimate"] = {{"solid_impedance", z_s}, {"gamma_over_impedance", impedance_ratio_}};
    if (impedance_ratio_ > 10 && settings_.max_iterations > 1)
      log->warn(
          "Algorithm 2: gamma_N1 = {:.4g} is {:.3g} times the solid's interface impedance m_s / |Gamma| / dt = "
          "{:.4g}: converged coupling iterations contract by about 1 - beta (Z_s + Z_f) / (Z_s + gamma_N1), so expect "
          "their number to grow like that ratio (coupling.robin_auto: solid sets gamma_N1 to the impedance)",
          gamma, impedance_ratio_, z_s);
  }
  consistent_damping_ = implicit && gamma > 0 && settings_.robin_mass == RobinMass::Consistent;
  if (consistent_damping_ && !solid_.supports_interface_mass()) {
    consistent_damping_ = false;
    log->warn(
        "the solid '{}' does not take the interface mass (supports_interface_mass): Algorithm 2's damping "
        "uses its own int N^T N, and the gamma_N1 terms do not cancel exactly at convergence "
        "(coupling.work_uncancelled in probes.csv)",
        solid_.name());
  }
  data["coupling"] = {{"algorithm", static_cast<int>(settings_.algorithm)},
                      {"gamma_n1", gamma},
                      {"fluid_penalty", settings_.fluid_penalty},
                      {"gamma_n2", settings_.nitsche_symmetry},
                      {"relaxation", settings_.relaxation},
                      {"max_iterations", settings_.max_iterations},
                      {"tolerance", settings_.tolerance},
                      {"acceleration", settings_.acceleration},
                      {"robin_mass", to_string(settings_.robin_mass)}};
  nlohmann::json measures = nlohmann::json::array();
  for (const auto& m : settings_.measures)
    measures.push_back({{"name", m.name()}, {"limit", m.limit}, {"strict", m.strict}});
  data["coupling"]["measures"] = measures;
  data["coupling"]["combine"] = settings_.combine_all ? "all" : "any";
  data["coupling"]["predictor"] = settings_.predictor;
  if (settings_.robin_auto != RobinAuto::None)
    data["coupling"]["robin_auto"] = {{"value", robin_auto_value_},
                                      {"mass_per_area", solid_interface_.mass_per_area},
                                      {"side", settings_.robin_auto == RobinAuto::Solid   ? "solid"
                                               : settings_.robin_auto == RobinAuto::Fluid ? "fluid"
                                                                                          : "both"}};
  if (settings_.scheme == CouplingScheme::Parallel) data["coupling"]["scheme"] = "parallel";
  if (accelerator_scheme(settings_.acceleration).quasi_newton) {
    const char* filters[] = {"qr1", "qr2", "qr3"};
    const char* restarts[] = {"none", "rs-0", "rs-ls", "rs-svd"};
    data["coupling"]["iqn"] = {
        {"reuse_steps", settings_.reuse_steps},
        {"filter", settings_.iqn_filter},
        {"filter_type", filters[static_cast<int>(settings_.iqn_filter_type)]},
        {"preconditioner", settings_.iqn_preconditioner == Preconditioner::None ? "none" : "residual-sum"}};
    if (settings_.acceleration == "iqn-imvj")
      data["coupling"]["iqn"]["imvj"] = {{"restart", restarts[static_cast<int>(settings_.imvj_restart)]},
                                         {"chunk_size", settings_.imvj_chunk_size},
                                         {"restart_reuse_steps", settings_.imvj_restart_reuse_steps},
                                         {"truncation", settings_.imvj_truncation}};
  }
  log->info("algorithm {}, gamma_N1 = {}, beta = {}, k_max = {}, tolerance = {}; {} solid / {} fluid interface nodes",
            to_string(settings_.algorithm), gamma, settings_.relaxation, settings_.max_iterations, settings_.tolerance,
            ns, fluid_interface.nodes());
  if (settings_.fluid_penalty != gamma)
    log->info("the fluid's Nitsche penalty gamma_f = {} is set apart from gamma_N1{}", settings_.fluid_penalty,
              implicit ? "" : " (Algorithm 1 uses gamma_f only: gamma_N1 has no effect)");
}

void Coupler::write_output(Run& r, const StepInfo& info, const InterfaceFields& fields) {
  ++r.output_requests;
  if (solid_.supports_output()) {
    Timer t(times_.solid);
    r.files_written["solid"] += solid_.write_output(info).size();
  }
  if (fluid_.supports_output()) {
    Timer t(times_.fluid);
    r.files_written["fluid"] += fluid_.write_output(info).size();
  }
  {
    Timer t(times_.coupler);
    r.interface_output->write(info.time, info.step, fields);
  }
  if (r.output_requests == 3)
    for (const auto& [side, ok, who] : {std::tuple{"solid", solid_.supports_output(), solid_.name()},
                                        std::tuple{"fluid", fluid_.supports_output(), fluid_.name()}})
      if (ok && r.files_written[side] == 0)
        r.log->warn(
            "time.output_every = {}: the {} '{}' wrote no VTK in {} requests (does its section turn "
            "output off? {})",
            r.time.output_every, side, who, r.output_requests,
            std::string(side) == "solid" ? "solid.output_every" : "fluid.output.vtk_every");
}

NodalMatrix Coupler::map_mass(Run& r, const FluidLoads& loads) {
  if (loads.interface_mass.rows() == 0) {
    if (!r.warned_no_fluid_mass && r.gamma > 0 && settings_.robin_mass == RobinMass::Consistent)
      r.log->warn(
          "the fluid '{}' does not send its interface mass M_f: the gamma_N1 terms use the solid's "
          "polyline int N^T N and cancel at convergence only where it equals H^T M_f H",
          fluid_.name());
    r.warned_no_fluid_mass = true;
    return NodalMatrix();
  }
  try {
    return map_.mass_to_solid(loads.interface_mass);
  } catch (const std::invalid_argument& e) {
    throw Stop{"failed", fmt::format("fluid '{}': {}", fluid_.name(), e.what())};
  }
}

void Coupler::start_state(Run& r) {
  if (r.checkpoints || resume_)
    for (const auto& [side, ok, who] : {std::tuple{"solid", solid_.supports_checkpoint(), solid_.name()},
                                        std::tuple{"fluid", fluid_.supports_checkpoint(), fluid_.name()}})
      if (!ok)
        throw Stop{"failed", fmt::format("{} needs checkpoints, which the {} '{}' does not support",
                                         resume_ ? "--resume" : "time.checkpoint_every", side, who)};
  find_restart(r);
  if (r.restart)
    load_restart(r);
  else
    initial_state(r);
  if (r.checkpoints)
    r.data["checkpoints"] = {{"every", r.time.checkpoint_every},
                             {"keep", r.time.checkpoint_keep},
                             {"written", 0},
                             {"seconds", 0.0},
                             {"folder", (out_dir_ / "checkpoints").string()}};
  if (r.restart) r.data["resumed_from_step"] = r.restart->step;
  r.data["wall_time_earlier_segments"] = r.wall_before;
}

void Coupler::find_restart(Run& r) {
  if (resume_) {
    std::vector<std::string> skipped;
    r.restart = r.store.newest(&skipped);
    for (const auto& why : skipped) r.log->warn("skipping checkpoint {}", why);
    if (!r.restart && !allow_fresh_start_)
      throw Stop{"failed", fmt::format("--resume: no complete checkpoint in {}{}", (out_dir_ / "checkpoints").string(),
                                       skipped.empty() ? std::string() : " (" + skipped.front() + ")")};
    if (!r.restart) r.log->warn("no complete checkpoint yet: starting again from step 0");
  }
  // A forked run (fsi run --from): OUT/forked_from.json names the checkpoint it started from;
  // at that checkpoint the scene may differ (the changes are listed in summary.json), and
  // its probes.csv and iterations.csv hold only the steps after it.
  if (std::filesystem::exists(out_dir_ / "forked_from.json")) {
    try {
      std::ifstream in(out_dir_ / "forked_from.json");
      r.fork = nlohmann::json::parse(in);
    } catch (const std::exception& e) {
      throw Stop{"failed", fmt::format("{}: does not parse ({})", (out_dir_ / "forked_from.json").string(), e.what())};
    }
    r.data["forked_from"] = r.fork;
  }
  r.fork_step = r.fork.is_object() ? r.fork.value("step", 0) : 0;
  r.fork_iterations = r.fork.is_object() ? r.fork.value("iterations", 0L) : 0L;
  r.at_fork = r.fork.is_object() && r.restart && r.restart->step == r.fork_step;
}

void Coupler::load_restart(Run& r) {
  const CheckpointStore::Loaded& restart = *r.restart;
  const int step = restart.step;
  auto diffs = parameter_differences(restart.manifest.value("parameters", nlohmann::json::object()), r.parameters);
  // A resumed run may be extended: time.end is the one key that may differ.
  if (!r.at_fork) {
    const auto end =
        std::find_if(diffs.begin(), diffs.end(), [](const std::string& d) { return d.rfind("time.end:", 0) == 0; });
    if (end != diffs.end()) {
      r.log->info("extended: {}", *end);
      r.data["extended"] = *end;
      diffs.erase(end);
    }
  }
  if (r.at_fork) {
    // The steps are numbered from t = 0 (t_n = n dt): another dt would put the fork at another
    // time and run to time.end in the wrong number of steps.
    for (const auto& d : diffs)
      if (d.rfind("time.dt:", 0) == 0)
        throw Stop{"failed", fmt::format("--from {}: a fork keeps the time step ({}); start a run with another "
                                         "time.dt from rest, or from another run's fluid state (--initial-state)",
                                         restart.dir.string(), d)};
    r.data["forked_from"]["changed"] = diffs;
    for (const auto& d : diffs) r.log->info("forked with {}", d);
  } else if (!diffs.empty()) {
    std::string list;
    for (const auto& d : diffs) list += "\n  " + d;
    throw Stop{"failed", fmt::format("--resume: the scene differs from the one checkpoint {} was written with "
                                     "({} key(s)):{}",
                                     restart.dir.string(), diffs.size(), list)};
  }
  for (const char* part : {"solid", "fluid", "coupler"})
    if (!restart.parts.count(part))
      throw Stop{"failed", fmt::format("checkpoint {} has no '{}' part", restart.dir.string(), part)};
  r.log->info("resuming from the checkpoint of step {} (t = {}) in {}", step, restart.time, restart.dir.string());
  {
    Timer t(times_.solid);
    solid_.load_checkpoint(step, restart.time, restart.parts.at("solid"));
  }
  {
    Timer t(times_.fluid);
    fluid_.load_checkpoint(step, restart.time, restart.parts.at("fluid"));
  }
  const StateArchive c =
      StateArchive::parse(restart.parts.at("coupler"), "coupler checkpoint of step " + std::to_string(step));
  if (c.integer("step") != step)
    throw Stop{"failed",
               fmt::format("checkpoint {}: coupler part is of step {}", restart.dir.string(), c.integer("step"))};
  read_coupler_state(r, c);
  if (r.at_fork) convert_forked_predictor(r, c);
  r.wall_before = restart.manifest.value("wall_seconds", 0.0);
  r.out.steps = step;
  r.out.resumed_from = step;
}

void Coupler::read_coupler_state(Run& r, const StateArchive& c) {
  State& st = r.state;
  const Eigen::Index nv = r.nv;
  const Eigen::Index ns = static_cast<Eigen::Index>(solid_interface_.nodes());
  const std::string dir = r.restart->dir.string();
  st.force_n = c.vector("force_n", nv);
  st.force_nm1 = c.vector("force_nm1", nv);
  // Before the predictors' longer history: F_n and F_{n-1}.
  st.force_nm2 = c.has("force_nm2") ? c.vector("force_nm2", nv) : st.force_nm1;
  st.force_nm3 = c.has("force_nm3") ? c.vector("force_nm3", nv) : st.force_nm2;
  st.forces_known = c.has("forces_known") ? static_cast<int>(c.integer("forces_known")) : 2;
  st.d_s_prev = c.vector("d_s_prev", nv);
  st.d_f_prev = c.vector("d_f_prev", st.d_f_prev.size());
  if (c.has("v_s_prev")) st.v_s_prev = c.vector("v_s_prev", nv);
  if (c.has("work_uncancelled")) st.work_uncancelled = c.real("work_uncancelled");
  if (c.has("mapped_mass.values")) {
    const Eigen::VectorXd rows = c.vector("mapped_mass.rows"), cols = c.vector("mapped_mass.cols"),
                          values = c.vector("mapped_mass.values");
    if (rows.size() != values.size() || cols.size() != values.size())
      throw Stop{"failed", fmt::format("checkpoint {}: coupler part has a malformed mapped_mass", dir)};
    std::vector<Eigen::Triplet<double>> t;
    for (Eigen::Index k = 0; k < values.size(); ++k) {
      const auto row = static_cast<Eigen::Index>(rows[k]), col = static_cast<Eigen::Index>(cols[k]);
      if (row < 0 || row >= ns || col < 0 || col >= ns)
        throw Stop{"failed", fmt::format("checkpoint {}: coupler mapped_mass entry ({}, {}) outside {} nodes", dir, row,
                                         col, ns)};
      t.emplace_back(row, col, values[k]);
    }
    st.mapped_mass.resize(ns, ns);
    st.mapped_mass.setFromTriplets(t.begin(), t.end());
  } else if (r.implicit && r.gamma > 0) {
    r.log->warn(
        "checkpoint {} holds no interface mass (an earlier version): the first solve of step {} uses the "
        "solid's own int N^T N",
        dir, r.restart->step + 1);
  }
  st.work_solid = c.real("work_solid");
  st.work_fluid = c.real("work_fluid");
  st.work_fluid_on_solid = c.real("work_fluid_on_solid");
  r.out.iterations = static_cast<long>(c.integer("iterations"));
  if (c.has("parallel.scale")) {
    const Eigen::VectorXd scale = c.vector("parallel.scale", 3);
    std::copy(scale.data(), scale.data() + 3, st.scale);
    // Checkpoints before the floor: the scale is the largest known.
    const Eigen::VectorXd peak = c.has("parallel.peak") ? c.vector("parallel.peak", 3) : scale;
    std::copy(peak.data(), peak.data() + 3, st.peak);
  }
  r.accelerator->load(c, "accelerator.");
}

void Coupler::convert_forked_predictor(Run& r, const StateArchive& c) {
  // F_n holds the algorithm's own Robin part: Algorithm 2's force is the load the solid
  // felt plus gamma_N1 C v_n. Forked into another algorithm or gamma_N1, convert it (the
  // predictor of the next step), and drop the accelerator's reused secant pairs (they
  // live in the old force's space).
  const auto& old =
      r.restart->manifest.value("parameters", nlohmann::json::object()).value("coupling", nlohmann::json::object());
  auto number = [](const nlohmann::json& j, const char* key, double fallback) {
    if (!j.contains(key)) return fallback;
    const auto& v = j.at(key);
    return v.is_number() ? v.get<double>() : v.is_string() ? std::stod(v.get<std::string>()) : fallback;
  };
  const double gamma = r.gamma;
  const int old_algorithm = static_cast<int>(number(old, "algorithm", static_cast<double>(settings_.algorithm)));
  const double old_gamma = number(old, "gamma_n1", gamma);
  if (old_algorithm == static_cast<int>(settings_.algorithm) && old_gamma == gamma) return;
  State& st = r.state;
  const NodalMatrix c_mass = st.mapped_mass.rows() > 0 ? st.mapped_mass : nodal_interface_mass(solid_interface_, {});
  if (!c.has("v_s_prev"))
    r.log->warn(
        "checkpoint {} holds no interface velocity (an earlier version): the first step's predictor "
        "keeps the old algorithm's force",
        r.restart->dir.string());
  else {
    for (Eigen::VectorXd* f : {&st.force_n, &st.force_nm1, &st.force_nm2, &st.force_nm3}) {
      if (old_algorithm == 2 && old_gamma > 0) *f -= old_gamma * apply_nodal(c_mass, st.v_s_prev);
      if (r.implicit && gamma > 0) *f += gamma * apply_nodal(c_mass, st.v_s_prev);
    }
    r.data["forked_from"]["predictor_converted"] = true;
  }
  r.accelerator = make_accelerator(settings_);
  r.log->info(
      "forked from algorithm {} (gamma_N1 {}) into algorithm {} (gamma_N1 {}): the force predictor "
      "converted, the reused secant pairs dropped",
      old_algorithm, old_gamma, static_cast<int>(settings_.algorithm), gamma);
}

void Coupler::initial_state(Run& r) {
  State& st = r.state;
  const Eigen::VectorXd &d_s = st.d_s_prev, &v_s = st.v_s_prev;  // the scene's initial state
  FluidLoads loads;
  {
    Timer t(times_.fluid);
    loads = fluid_.initial_loads(map_.to_fluid(d_s), map_.to_fluid(v_s));
  }
  Timer t(times_.coupler);
  st.mapped_mass = map_mass(r, loads);
  st.force_n = -robin_force(map_.to_solid(loads.traction_force), map_.to_solid(loads.velocity_integral), v_s, d_s,
                            st.mapped_mass);
  st.force_nm1 = st.force_nm2 = st.force_nm3 = st.force_n;
  if (r.time.output_every > 0) {  // the initial state, t = 0
    write_output(r, StepInfo{0.0, r.time.dt, 0, 0},
                 InterfaceFields{d_s, v_s, st.force_n, map_.to_solid(loads.traction_force),
                                 map_.to_solid(loads.velocity_integral), map_.to_fluid(d_s), map_.to_fluid(v_s),
                                 loads.traction_force, loads.velocity_integral});
  }
}

void Coupler::open_tables(Run& r) {
  std::vector<std::string> iteration_columns{"step",
                                             "time",
                                             "iteration",
                                             "residual",
                                             "force_norm",
                                             "solid_newton",
                                             "fluid_iterations",
                                             "traction_change",
                                             "traction_norm",
                                             "displacement_change",
                                             "displacement_norm",
                                             "velocity_change",
                                             "velocity_norm"};
  for (const auto& m : settings_.measures) iteration_columns.push_back(m.name());
  if (settings_.scheme == CouplingScheme::Parallel) iteration_columns.push_back("interface_gap");
  const bool resume_tables = r.restart && !r.at_fork;
  const auto kept_steps = resume_tables ? static_cast<std::size_t>(r.restart->step - r.fork_step) : 0;
  r.probes.emplace(resume_tables ? ProbeTable::resume(out_dir_ / "probes.csv", kept_steps)
                                 : ProbeTable(out_dir_ / "probes.csv"));
  r.iterations = resume_tables ? CsvWriter::resume(out_dir_ / "iterations.csv",
                                                   static_cast<std::size_t>(r.out.iterations - r.fork_iterations),
                                                   iteration_columns)
                               : CsvWriter(out_dir_ / "iterations.csv", iteration_columns);
  // Wall time per step (not byte-identical across runs, so apart from probes.csv): cumulative
  // seconds of the run, its fluid and solid requests, for cost per simulated second.
  const std::vector<std::string> timing_columns{"step", "time", "wall", "fluid", "solid", "iterations"};
  const auto timing_path = out_dir_ / "timing.csv";
  r.timing = resume_tables && std::filesystem::exists(timing_path)
                 ? CsvWriter::resume(timing_path, kept_steps, timing_columns)
                 : CsvWriter(timing_path, timing_columns);
  r.progress.emplace("coupler", r.time.steps, r.out.steps);
  r.segment_start = now();
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
  step.d_iter_prev = st.d_s_prev;
  step.v_iter_prev = st.v_s_prev;
  if (settings_.scheme == CouplingScheme::Parallel) {  // the fluid's first interface state
    step.x_d = st.d_s_prev + r.time.dt * st.v_s_prev;
    step.x_v = st.v_s_prev;
  }
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

Coupler::Update Coupler::coupling_iteration(Run& r, Step& step) {
  if (settings_.scheme == CouplingScheme::Parallel) return parallel_iteration(r, step);
  const int n = step.n, k = step.k;
  const double gamma = r.gamma;
  const StepInfo info{step.t_np1, r.time.dt, n, k};
  Update u = begin_iteration(r, step);
  Iterate& it = u.iterate;
  const SolidStepResult& s = it.s;
  {
    Timer t(times_.solid);
    it.s = solid_.solve_step(info, step.force);
  }
  if (!all_finite(s.interface_displacement) || !all_finite(s.interface_velocity))
    throw Stop{"diverged", fmt::format("solid returned a non-finite interface state at step {} iteration {}", n, k)};
  Eigen::VectorXd v_f;
  {
    Timer t(times_.coupler);
    it.d_f = map_.to_fluid(s.interface_displacement);
    v_f = map_.to_fluid(s.interface_velocity);
  }
  {
    Timer t(times_.fluid);
    it.loads = fluid_.solve_step(info, it.d_f, v_f);
  }
  Eigen::VectorXd traction_change;
  {
    Timer t(times_.coupler);
    it.mass = map_mass(r, it.loads);
    const Eigen::VectorXd fs = map_.to_solid(it.loads.traction_force), fv = map_.to_solid(it.loads.velocity_integral);
    const Eigen::VectorXd f_star = robin_force(fs, fv, s.interface_velocity, s.interface_displacement, it.mass);
    // The physical traction H^T R = f_sigma - gamma_f (f_v - M_f v_s) (the fluid's reaction,
    // without its penalty part), and its mismatch with what the solid felt: its load
    // F^(k) minus its own Robin damping gamma C v_s.
    const double gamma_f = settings_.fluid_penalty;
    it.traction =
        gamma_f > 0 ? Eigen::VectorXd(fs - gamma_f * (fv - apply_nodal(physical_mass(s.interface_displacement, it.mass),
                                                                       s.interface_velocity)))
                    : fs;
    traction_change = it.traction + step.force;
    if (it.damping.rows() > 0) traction_change -= gamma * apply_nodal(it.damping, s.interface_velocity);
    // r_k = -F* - F^(k); F^(k+1) = F^(k) + beta r_k is the paper's relaxation
    // (acceleration.hpp for Aitken and IQN-ILS).
    u.relaxed = r.accelerator->update(step.force, -f_star - step.force);
    r.state.mapped_mass = it.mass;  // the next solid solve's damping (Algorithm 2)
  }
  if (!all_finite(u.relaxed))
    throw Stop{"diverged", fmt::format("non-finite interface force at step {} iteration {}", n, k)};
  measure(step, u, traction_change);
  return u;
}

// The iteration's residual quantities (force change, traction mismatch, displacement and
// velocity change) and their sizes, for the convergence measures and iterations.csv.
void Coupler::measure(Step& step, Update& u, const Eigen::VectorXd& traction_change) const {
  const SolidStepResult& s = u.iterate.s;
  u.norm = u.relaxed.norm();
  u.change = (u.relaxed - step.force).norm();
  step.residual = u.change / std::max(u.norm, settings_.residual_floor);
  const double r_quantity[4] = {u.change, traction_change.norm(), (s.interface_displacement - step.d_iter_prev).norm(),
                                (s.interface_velocity - step.v_iter_prev).norm()};
  const double q_quantity[4] = {u.norm, u.iterate.traction.norm(), s.interface_displacement.norm(),
                                s.interface_velocity.norm()};
  std::copy(r_quantity, r_quantity + 4, u.r_quantity);
  std::copy(q_quantity, q_quantity + 4, u.q_quantity);
  step.d_iter_prev = s.interface_displacement;
  step.v_iter_prev = s.interface_velocity;
}

double Coupler::parallel_gap_limit() const {
  double limit = std::numeric_limits<double>::infinity();
  for (const auto& m : settings_.measures) limit = std::min(limit, m.limit);
  return limit;
}

// Parallel (Jacobi): the solid with F^(k) and the fluid with x^(k) = (d^(k), v^(k)) at once,
// then the accelerator on the stacked, scaled [d; v; F] with the residual
// [d_s - d^(k); v_s - v^(k); -F*(x^(k)) - F^(k)].
Coupler::Update Coupler::parallel_iteration(Run& r, Step& step) {
  const int n = step.n, k = step.k;
  const StepInfo info{step.t_np1, r.time.dt, n, k};
  Update u = begin_iteration(r, step);
  Iterate& it = u.iterate;
  Eigen::VectorXd v_f;
  {
    Timer t(times_.coupler);
    it.d_f = map_.to_fluid(step.x_d);
    v_f = map_.to_fluid(step.x_v);
  }
  // Each server has its own connection: the solid's request goes from a second thread while
  // this one waits for the fluid; both wait for the other before anything is thrown.
  auto solid_job = std::async(std::launch::async, [&] {
    Timer t(times_.solid);
    return solid_.solve_step(info, step.force);
  });
  try {
    Timer t(times_.fluid);
    it.loads = fluid_.solve_step(info, it.d_f, v_f);
  } catch (...) {
    solid_job.wait();
    throw;
  }
  it.s = solid_job.get();
  const SolidStepResult& s = it.s;
  if (!all_finite(s.interface_displacement) || !all_finite(s.interface_velocity))
    throw Stop{"diverged", fmt::format("solid returned a non-finite interface state at step {} iteration {}", n, k)};
  Eigen::VectorXd traction_change;
  {
    Timer t(times_.coupler);
    it.mass = map_mass(r, it.loads);
    const Eigen::VectorXd fs = map_.to_solid(it.loads.traction_force), fv = map_.to_solid(it.loads.velocity_integral);
    // F* of the interface state the fluid was given.
    const Eigen::VectorXd f_star = robin_force(fs, fv, step.x_v, step.x_d, it.mass);
    const double gamma_f = settings_.fluid_penalty;
    it.traction = gamma_f > 0
                      ? Eigen::VectorXd(fs - gamma_f * (fv - apply_nodal(physical_mass(step.x_d, it.mass), step.x_v)))
                      : fs;
    traction_change = it.traction + step.force;
    if (it.damping.rows() > 0) traction_change -= r.gamma * apply_nodal(it.damping, s.interface_velocity);
    stacked_update(r, step, u, -f_star - step.force);
    r.state.mapped_mass = it.mass;
  }
  if (!all_finite(u.relaxed) || !all_finite(u.next_d) || !all_finite(u.next_v))
    throw Stop{"diverged", fmt::format("non-finite interface state at step {} iteration {}", n, k)};
  measure(step, u, traction_change);
  u.gap = (u.next_d - step.x_d).norm() / std::max(u.next_d.norm(), settings_.residual_floor);
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

void Coupler::stacked_update(Run& r, const Step& step, Update& u, const Eigen::VectorXd& r_force) {
  const SolidStepResult& s = u.iterate.s;
  const Eigen::Index m = step.force.size();
  const Eigen::VectorXd* x[3] = {&step.x_d, &step.x_v, &step.force};
  const Eigen::VectorXd res[3] = {s.interface_displacement - step.x_d, s.interface_velocity - step.x_v, r_force};
  double* scale = r.state.scale;
  if (step.k == 1) {
    bool renewed = false;
    for (int b = 0; b < 3; ++b) {
      const double size = std::max({x[b]->norm(), (*x[b] + res[b]).norm(), kScaleFloor * r.state.peak[b]});
      if (size > settings_.residual_floor && (scale[b] == 0 || size > 10 * scale[b] || size < 0.1 * scale[b])) {
        scale[b] = size, renewed = true;
        r.state.peak[b] = std::max(r.state.peak[b], size);
      }
    }
    if (renewed && step.n > 1) {
      r.accelerator = make_accelerator(settings_);
      r.accelerator->begin_step();
    }
  }
  Eigen::VectorXd xs(3 * m), rs(3 * m);
  for (int b = 0; b < 3; ++b) {
    const double w = scale[b] > 0 ? 1 / scale[b] : 1.0;
    xs.segment(b * m, m) = w * *x[b];
    rs.segment(b * m, m) = w * res[b];
  }
  const Eigen::VectorXd y = r.accelerator->update(xs, rs);
  u.stacked_change = (y - xs).norm();
  u.stacked_residual = u.stacked_change / std::max(y.norm(), settings_.residual_floor);
  Eigen::VectorXd* out[3] = {&u.next_d, &u.next_v, &u.relaxed};
  for (int b = 0; b < 3; ++b) *out[b] = (scale[b] > 0 ? scale[b] : 1.0) * y.segment(b * m, m);
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
  if (settings_.scheme == CouplingScheme::Parallel) row_values.push_back(u.gap);
  r.iterations.row(row_values);
  step.last = u.iterate;
  step.last.force_applied = step.force;
  step.force = u.relaxed;
  const bool parallel = settings_.scheme == CouplingScheme::Parallel;
  if (parallel) step.x_d = u.next_d, step.x_v = u.next_v, step.gap = u.gap;
  ++r.out.iterations;
  if (u.norm > settings_.force_limit)
    throw Stop{"diverged", fmt::format("interface force norm {:.3e} exceeds force_limit {:.3e} at step {} "
                                       "iteration {} (loosely coupled instability?)",
                                       u.norm, settings_.force_limit, n, k)};
  // Parallel: growth is watched on the stacked, scaled [d; v; F] (its force part may start at 0).
  const double residual = parallel ? u.stacked_residual : step.residual;
  const double change = parallel ? u.stacked_change : u.change;
  if (k == 1) step.first_residual = residual, step.first_change = change;
  if (settings_.measures.empty()) return false;
  // Parallel: the fluid's interface state must have converged too (below the measures' limit).
  if (met && (!parallel || u.gap < parallel_gap_limit())) return true;
  step.history.push_back(residual);
  // Geometric growth keeps the relative residual constant: watch the absolute change.
  if (k > 1 && (residual > settings_.divergence_factor * std::max(step.first_residual, settings_.residual_floor) ||
                change > settings_.divergence_factor * std::max(step.first_change, settings_.residual_floor)))
    throw Stop{"diverged",
               fmt::format("coupling residual grew: {} from {:.3e} to {:.3e} "
                           "(relative {:.3e} to {:.3e}) at step {} iteration {} "
                           "(relaxation {} above the stability limit?)",
                           parallel ? "|x^(k+1) - x^(k)| (scaled [d; v; F])" : "|F^(k+1) - F^(k)|", step.first_change,
                           change, step.first_residual, residual, n, k, settings_.relaxation)};
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
    write_output(r, accepted,
                 InterfaceFields{last.s.interface_displacement, last.s.interface_velocity, last.force_applied,
                                 map_.to_solid(last.loads.traction_force), map_.to_solid(last.loads.velocity_integral),
                                 last.d_f, map_.to_fluid(last.s.interface_velocity), last.loads.traction_force,
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
  const double gamma = r.gamma;
  const SolidStepResult& s = last.s;
  st.work_solid += last.force_applied.dot(s.interface_displacement - st.d_s_prev);
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
  Eigen::VectorXd load = last.force_applied;
  if (last.damping.rows() > 0) load -= gamma * apply_nodal(last.damping, v);
  double uncancelled = 0;
  const double g = r.implicit ? gamma : settings_.fluid_penalty;  // the parameter of C's term
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

void Coupler::save_checkpoint(Run& r, int n, double t_np1) {
  Timer t(times_.checkpoint);
  const State& st = r.state;
  std::map<std::string, std::string> parts;
  parts["solid"] = solid_.save_checkpoint(n, t_np1);
  parts["fluid"] = fluid_.save_checkpoint(n, t_np1);
  StateArchive c;
  c.put("step", static_cast<std::int64_t>(n));
  c.put("force_n", st.force_n);
  c.put("force_nm1", st.force_nm1);
  c.put("force_nm2", st.force_nm2);
  c.put("force_nm3", st.force_nm3);
  c.put("forces_known", static_cast<std::int64_t>(st.forces_known));
  c.put("d_s_prev", st.d_s_prev);
  c.put("d_f_prev", st.d_f_prev);
  c.put("work_solid", st.work_solid);
  c.put("work_fluid", st.work_fluid);
  c.put("work_fluid_on_solid", st.work_fluid_on_solid);
  c.put("work_uncancelled", st.work_uncancelled);
  c.put("v_s_prev", st.v_s_prev);
  if (st.mapped_mass.rows() > 0) {
    std::vector<double> rows, cols, values;
    for (int col = 0; col < st.mapped_mass.outerSize(); ++col)
      for (NodalMatrix::InnerIterator it(st.mapped_mass, col); it; ++it)
        rows.push_back(double(it.row())), cols.push_back(double(it.col())), values.push_back(it.value());
    c.put("mapped_mass.rows", rows);
    c.put("mapped_mass.cols", cols);
    c.put("mapped_mass.values", values);
  }
  c.put("iterations", static_cast<std::int64_t>(r.out.iterations));
  if (settings_.scheme == CouplingScheme::Parallel)
    c.put("parallel.scale", std::vector<double>(st.scale, st.scale + 3));
  c.put("parallel.peak", std::vector<double>(st.peak, st.peak + 3));
  r.accelerator->save(c, "accelerator.");
  parts["coupler"] = c.serialize();
  nlohmann::json manifest = {{"scene", r.data.value("scene", std::string())},
                             {"scene_file", scene_.origin()},
                             {"overrides", scene_.overrides()},
                             {"parameters", r.parameters},
                             {"iterations", r.out.iterations},
                             {"wall_seconds", r.wall_before + (now() - r.segment_start)}};
  const auto written = r.store.write(n, t_np1, manifest, parts);
  auto& info = r.data["checkpoints"];
  info["written"] = info.value("written", 0) + 1;
  info["last_step"] = n;
  info["last_bytes"] = written.bytes;
  info["parts_bytes"] = {
      {"solid", parts["solid"].size()}, {"fluid", parts["fluid"].size()}, {"coupler", parts["coupler"].size()}};
}

}  // namespace fsi::coupling
