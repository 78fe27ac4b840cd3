#include "fsi/common/standalone.hpp"

#include <fmt/format.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdlib>

#include "fsi/common/log.hpp"
#include "fsi/common/log_file.hpp"
#include "fsi/common/run_report.hpp"
#include "fsi/common/scene_reader.hpp"
#include "fsi/common/write_check.hpp"

namespace fsi {
namespace {

std::atomic<int> g_standalone_signal{0};
extern "C" void on_standalone_signal(int sig) { g_standalone_signal = sig; }

double now_seconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

struct Interrupted {
  std::string reason;
};

template <class Model, class SetupFn, class StepFn>
int run_loop(std::unique_ptr<Model>& model, const Scene& scene, const std::filesystem::path& out_dir,
             const char* runner, const char* section, SetupFn&& setup_fn, StepFn&& step_fn, double& compute_time) {
  add_log_file(out_dir / (std::string(runner) + ".log"));  // OUT/solid_server.log, OUT/fluid_server.log
  auto log = logger(runner);
  RunReport report(out_dir, scene, runner);
  const double start = now_seconds();
  int steps_done = 0;
  long iterations = 0;                 // the solver's nonlinear iterations (Newton / fluid solves), all steps
  bool write_failed = false;           // an output file could not be written (a full disk): exit 74
  std::map<std::string, double> last;  // the last step's probes, named as in probes.csv
  std::signal(SIGINT, on_standalone_signal);
  std::signal(SIGTERM, on_standalone_signal);
  try {
    scene.name();
    const TimeSettings time = read_time(scene);
    if (time.checkpoint_every > 0)
      log->warn("time.checkpoint_every: checkpoints are written by coupled runs only; this {} run writes none",
                section);
    setup_fn(time);
    report.data()["setup_seconds"] = now_seconds() - start;
    for (const auto& [k, v] : model->sizes())  // counts: integers in the JSON
      report.data()[k] =
          v == std::floor(v) && std::abs(v) < 9e15 ? nlohmann::json(static_cast<std::int64_t>(v)) : nlohmann::json(v);
    if (time.output_every > 0) model->write_output(StepInfo{0.0, time.dt, 0, 0});  // the initial state
    ProbeTable probes(out_dir / "probes.csv");
    Progress progress(runner, time.steps);
    int step_now = 1;  // a long step's nonlinear iterations show every 2 s (Progress::within)
    model->on_iteration([&](const std::string& text) { progress.within(step_now, text); });
    for (int n = 1; n <= time.steps; ++n) {
      step_now = n;
      if (g_standalone_signal)
        throw Interrupted{
            fmt::format("interrupted by {} before step {}", g_standalone_signal == SIGINT ? "SIGINT" : "SIGTERM", n)};
      StepInfo info{n * time.dt, time.dt, n, 0};
      const double t0 = now_seconds();
      auto [values, step_iterations] = step_fn(info);
      compute_time += now_seconds() - t0;
      iterations += step_iterations;
      for (const auto& [k, v] : values)
        if (!std::isfinite(v))
          throw SolverError(fmt::format("probe '{}' is not finite at step {} (t = {})", k, n, info.time));
      std::map<std::string, double> named;
      for (const auto& [k, v] : values) named[std::string(section) + "." + k] = v;
      probes.add(info.time, named);
      last = std::move(named);
      if (time.output_every > 0 && n % time.output_every == 0) model->write_output(info);
      steps_done = n;
      report.data()["steps"] = steps_done;
      report.data()["solver_iterations"] = iterations;
      if (n == time.steps || n % 10 == 0) {
        report.data()["wall_time"] = {{"total", now_seconds() - start}, {section, compute_time}};
        if (model && !model->timings().empty()) report.data()[std::string(section) + "_breakdown"] = model->timings();
        report.write();
      }
      progress.update(n, info.time, fmt::format("iterations {}", step_iterations));
    }
    report.set_status("completed");
    report.data()["wall_time"] = {{"total", now_seconds() - start}, {section, compute_time}};
    if (model && !model->timings().empty()) report.data()[std::string(section) + "_breakdown"] = model->timings();
  } catch (const Interrupted& e) {
    report.set_status("interrupted", e.reason);
  } catch (const ConfigError& e) {
    report.set_status("failed", std::string("configuration: ") + e.what());
  } catch (const SolverError& e) {
    report.set_status("diverged", fmt::format("{} solver failed at step {}: {}", section, steps_done + 1, e.what()));
  } catch (const std::exception& e) {
    report.set_status("failed", e.what());
    write_failed = is_write_failure(e.what());
  }
  report.data()["steps"] = steps_done;
  report.data()["solver_iterations"] = iterations;
  if (!last.empty()) report.data()["final"] = last;  // the last row of probes.csv
  report.data()["wall_time"] = {{"total", now_seconds() - start}, {section, compute_time}};
  if (model && !model->timings().empty()) report.data()[std::string(section) + "_breakdown"] = model->timings();
  try {
    report.write();
  } catch (const std::exception& e) {  // a full disk: the status goes to stderr instead
    log->error("{}; the run's status is not in it", e.what());
    write_failed = true;
  }
  const std::string status = report.data()["status"];
  if (status != "completed" || write_failed) {
    log->error("{}: {}", status, report.data()["reason"].get<std::string>());
    return write_failed ? 74 : status == "diverged" ? 2 : status == "interrupted" ? 130 : 1;
  }
  log->info("completed {} steps in {:.2f} s; results in {}", steps_done, now_seconds() - start, out_dir.string());
  return 0;
}

}  // namespace

const schema::Key& time_section() {
  using namespace schema;
  static const Key time = [] {
    Key k =
        section("time", "time stepping (every runner)",
                {
                    number("dt", "time step").req().gt(0).in_unit("s"),
                    number("end", "final time; a whole number of time steps").req().gt(0).in_unit("s"),
                    integer("output_every",
                            "VTK of both solvers (and the coupling interfaces) every N steps and at "
                            "t = 0; 0 = none")
                        .def("0")
                        .ge(0)
                        .in_unit("steps"),
                    choice("vtk_format", {"binary", "ascii"},
                           "VTK encoding: binary = ParaView's default (arrays zlib-compressed in one appended block, "
                           "doubles exact), ascii = text with 10 significant digits")
                        .def("binary"),
                    integer("checkpoint_every",
                            "coupled runs: a checkpoint of both solvers and the coupler every N "
                            "accepted steps; 0 = none")
                        .def("0")
                        .ge(0)
                        .in_unit("steps"),
                    integer("checkpoint_keep", "the newest K complete checkpoints are kept").def("2").ge(1),
                })
            .req();
    k.check = [](const Scene& scene) { (void)read_time(scene); };  // end: a whole number of steps
    return k;
  }();
  return time;
}

TimeSettings read_time(const Scene& scene) {
  const schema::Reader t(scene.section("time"), time_section());
  TimeSettings s;
  s.dt = t.get<double>("dt");
  s.end = t.get<double>("end");
  s.output_every = t.get<int>("output_every");
  if (!(s.dt > 0)) t.fail("dt", "must be positive");
  if (!(s.end > 0)) t.fail("end", "must be positive");
  if (s.output_every < 0) t.fail("output_every", "must be >= 0");
  s.vtk_format = read_vtk_format(scene);
  s.checkpoint_every = t.get<int>("checkpoint_every");
  s.checkpoint_keep = t.get<int>("checkpoint_keep");
  if (s.checkpoint_every < 0) t.fail("checkpoint_every", "must be >= 0 (0 = no checkpoints)");
  if (s.checkpoint_keep < 1) t.fail("checkpoint_keep", "must be >= 1");
  s.steps = static_cast<int>(std::llround(s.end / s.dt));
  if (s.steps < 1) t.fail("end", "is shorter than one time step");
  // A run ends at steps * dt: refuse an end that is not (to round-off) a whole number of steps.
  if (std::abs(s.steps * s.dt - s.end) > 1e-9 * s.end) {
    const long below = static_cast<long>(std::floor(s.end / s.dt)), above = below + 1;
    t.fail("end", fmt::format("({}) must be a whole number of time steps dt = {}: end / dt = {:.6g}; use {:.10g} "
                              "({} steps) or {:.10g} ({} steps)",
                              s.end, s.dt, s.end / s.dt, below * s.dt, below, above * s.dt, above));
  }
  return s;
}

VtkFormat read_vtk_format(const Scene& scene) {
  const schema::Reader t(scene.section("time"), time_section());
  return parse_vtk_format(t.get<std::string>("vtk_format"));  // the declaration's values: binary, ascii
}

namespace {
// The seconds between progress lines: 2, or $FSI_PROGRESS_INTERVAL (tests: 0 = every line).
double progress_interval() {
  const char* env = std::getenv("FSI_PROGRESS_INTERVAL");
  if (!env || !*env) return 2.0;
  char* end = nullptr;
  const double v = std::strtod(env, &end);
  return end != env && std::isfinite(v) && v >= 0 ? v : 2.0;
}
}  // namespace

Progress::Progress(std::string logger_name, int total_steps, int first_step)
    : logger_name_(std::move(logger_name)),
      total_(total_steps),
      first_(first_step),
      interval_(progress_interval()),
      start_(now_seconds()),
      step_start_(start_) {}

void Progress::update(int step, double time, const std::string& extra) {
  const double now = now_seconds();
  step_start_ = now;
  if (first_done_ < 0) first_done_ = now, first_done_step_ = step;
  if (now - last_ < interval_ && step != total_) return;
  last_ = now;
  const double elapsed = now - start_;
  double per_step = 0;
  if (step > first_done_step_)
    per_step = (now - first_done_) / (step - first_done_step_);
  else if (step > first_)
    per_step = elapsed / (step - first_);
  logger(logger_name_)
      ->info("step {}/{} t={:.5g} {} elapsed {:.1f} s, ETA {:.1f} s", step, total_, time, extra, elapsed,
             per_step * (total_ - step));
}

void Progress::within(int step, const std::string& extra) {
  const double now = now_seconds();
  if (now - step_start_ < interval_ || now - last_ < interval_) return;  // short steps: the line per step suffices
  last_ = now;
  logger(logger_name_)->info("step {}/{} {} (this step: {:.1f} s so far)", step, total_, extra, now - step_start_);
}

int run_standalone_solid(const SolidFactory& factory, const Scene& scene, const std::filesystem::path& out_dir) {
  double compute = 0;
  std::unique_ptr<SolidModel> model;
  return run_loop(
      model, scene, out_dir, "solid_server", "solid",
      [&](const TimeSettings& time) {
        const auto section = scene.section("solid");
        model = make_model(factory, section, "solid");
        model->configure(
            section, SolidSetup{time.dt, time.end, 0.0,
                                time.output_every > 0 ? out_dir / "vtk" : std::filesystem::path(), time.vtk_format});
        scene.check_all_used();
      },
      [&](const StepInfo& info) {
        const auto n = model->interface().nodes();
        const int newton = model->solve_step(info, Eigen::VectorXd::Zero(2 * n)).newton_iterations;
        return std::pair{model->accept_step(info), newton};
      },
      compute);
}

int run_standalone_fluid(const FluidFactory& factory, const Scene& scene, const std::filesystem::path& out_dir) {
  double compute = 0;
  std::unique_ptr<FluidModel> model;
  return run_loop(
      model, scene, out_dir, "fluid_server", "fluid",
      [&](const TimeSettings& time) {
        const auto section = scene.section("fluid");
        model = make_model(factory, section, "fluid");
        model->configure(
            section, FluidSetup{time.dt, time.end, 0.0, -1.0,
                                time.output_every > 0 ? out_dir / "vtk" : std::filesystem::path(), time.vtk_format});
        scene.check_all_used();
      },
      [&](const StepInfo& info) {
        const auto n = model->interface().nodes();
        const int solves =
            model->solve_step(info, Eigen::VectorXd::Zero(2 * n), Eigen::VectorXd::Zero(2 * n)).nonlinear_iterations;
        return std::pair{model->accept_step(info), solves};
      },
      compute);
}

}  // namespace fsi
