// coupler: runs a scene's FSI time loop against a solid server and a fluid server.
//
// Sample runs (the launcher `fsi run` does all of this for you on loopback):
//   solid_server --bind 'tcp://127.0.0.1:*' --port-file s.port &
//   fluid_server --bind 'tcp://127.0.0.1:*' --port-file f.port &
//   coupler configs/sdof_model.yaml --solid $(cat s.port) --fluid $(cat f.port) --out runs/sdof
// Exit code: 0 completed, 2 diverged (the run's summary says why), 1 failed (also bad
// options), 130 interrupted (SIGINT/SIGTERM); with --recoverable, 75 when a server died or
// stopped answering (the launcher restarts it and resumes from the last checkpoint).
#include <fmt/format.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include "fsi/common/log.hpp"
#include "fsi/common/process.hpp"
#include "fsi/common/run_report.hpp"
#include "fsi/common/version.hpp"
#include "fsi/coupling/coupler.hpp"
#include "fsi/protocol/client.hpp"
#include "fsi/protocol/remote.hpp"
#include "fsi/transport/transport.hpp"

namespace {
extern "C" void on_signal(int) { fsi::coupling::Coupler::interrupt_flag() = true; }

using Clock = std::chrono::steady_clock;
using Logger = std::shared_ptr<spdlog::logger>;

struct Options {
  std::string scene_path, solid_endpoint, fluid_endpoint, out_dir = "out";
  std::vector<std::string> overrides;
  double timeout = 600, connect_timeout = 20;
  bool resume = false, force = false, recoverable = false, fresh_start = false, out_ready = false;
  std::string curve_keys, generate_keys;
};

// The two servers, once connected.
struct Servers {
  std::unique_ptr<fsi::protocol::RemoteSolid> solid;
  std::unique_ptr<fsi::protocol::RemoteFluid> fluid;
};

// ---- Process handling: options, the servers, the run.

// `coupler --generate-keys DIR` needs no scene: the exit code when asked, else -1.
int generate_keys_if_asked(int argc, char** argv) {
  for (int i = 1; i + 1 < argc; ++i)
    if (std::string(argv[i]) == "--generate-keys") {
      try {
        fsi::transport::generate_curve_keys(argv[i + 1]);
      } catch (const std::exception& e) {
        fsi::logger("coupler")->error("{}", e.what());
        return 1;
      }
      std::printf(
          "CURVE keys written to %s: server.key, server.key_secret, coupler.key, "
          "coupler.key_secret\n"
          "  servers:  --curve-keys %s (needs server.key_secret and coupler.key)\n"
          "  coupler:  --curve-keys %s (needs coupler.key_secret and server.key)\n",
          argv[i + 1], argv[i + 1], argv[i + 1]);
      return 0;
    }
  return -1;
}

// Parses the command line into `o` (handling --generate-keys first): the exit code when the
// process should end here (--help, --version, a bad option, keys written), else -1.
int parse_options(int argc, char** argv, Options& o) {
  CLI::App app{"FSI coupler"};
  app.set_version_flag("--version", fsi::version_line("coupler") + "\nprotocol fsi.v1, version " +
                                        std::to_string(fsi::protocol::kProtocolVersion));
  app.add_option("scene", o.scene_path, "scene file (configs/*.yaml)")->required();
  app.add_option("--solid", o.solid_endpoint, "solid server endpoint, e.g. tcp://127.0.0.1:5555")->required();
  app.add_option("--fluid", o.fluid_endpoint, "fluid server endpoint, e.g. tcp://127.0.0.1:5556")->required();
  app.add_option("--out", o.out_dir, "output folder");
  app.add_option("--set", o.overrides, "override a scene key: dotted.key=value");
  app.add_option("--timeout", o.timeout, "seconds to wait for any reply (a dead peer is detected at once)");
  app.add_option("--connect-timeout", o.connect_timeout, "seconds to wait for the handshake");
  app.add_flag("--resume", o.resume, "continue the run in --out from its newest complete checkpoint");
  app.add_flag("--force", o.force, "replace the results of an earlier run in --out");
  app.add_flag("--recoverable", o.recoverable,
               "exit with code 75 (instead of 1) when a server dies or stops answering, so that the "
               "launcher can restart it and resume (fsi run --recover)");
  app.add_flag("--resume-or-restart", o.fresh_start,
               "with --resume: start again from step 0 when there is no checkpoint yet");
  app.add_flag("--out-ready", o.out_ready, "the launcher has prepared --out")->group("");
  app.add_option("--curve-keys", o.curve_keys,
                 "encrypt and authenticate with ZeroMQ CURVE: the folder made by `fsi keys DIR` "
                 "(coupler.key_secret, "
                 "server.key)");
  app.add_option("--generate-keys", o.generate_keys, "write a new CURVE key folder and exit (what `fsi keys` runs)")
      ->group("");
  if (const int code = generate_keys_if_asked(argc, argv); code >= 0) return code;
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : 1;
  }
  return -1;
}

// Connects both servers (handshake), with the reply timeout and CURVE keys of the options.
void connect_servers(const Options& o, Servers& servers, fsi::RunReport& report, const Logger& log) {
  const auto connect = std::chrono::milliseconds(static_cast<long>(o.connect_timeout * 1000));
  const auto keys =
      o.curve_keys.empty() ? fsi::transport::CurveKeys{} : fsi::transport::load_curve_keys(o.curve_keys, "coupler");
  const auto wait = std::chrono::milliseconds(static_cast<long>(o.timeout * 1000));
  servers.solid = std::make_unique<fsi::protocol::RemoteSolid>(
      std::make_unique<fsi::protocol::ProtocolClient>(o.solid_endpoint, "solid server", connect, keys));
  servers.fluid = std::make_unique<fsi::protocol::RemoteFluid>(
      std::make_unique<fsi::protocol::ProtocolClient>(o.fluid_endpoint, "fluid server", connect, keys));
  servers.solid->client().set_timeout(wait);
  servers.fluid->client().set_timeout(wait);
  log->info("connected: solid '{}' at {}, fluid '{}' at {}", servers.solid->name(), o.solid_endpoint,
            servers.fluid->name(), o.fluid_endpoint);
  report.data()["servers"] = {{"solid", {{"name", servers.solid->name()}, {"endpoint", o.solid_endpoint}}},
                              {"fluid", {{"name", servers.fluid->name()}, {"endpoint", o.fluid_endpoint}}}};
}

void stop_servers(const Servers& servers, const std::string& status, const Logger& log) {
  try {
    if (servers.solid) servers.solid->stop(status);
  } catch (const std::exception& e) {
    log->warn("could not stop the solid server: {}", e.what());
  }
  try {
    if (servers.fluid) servers.fluid->stop(status);
  } catch (const std::exception& e) {
    log->warn("could not stop the fluid server: {}", e.what());
  }
}

// ---- summary.json.

// A resumed run keeps the history of its earlier segments (resumes, recoveries).
nlohmann::json earlier_history(const Options& o, const Logger& log) {
  nlohmann::json history = nlohmann::json::object();
  if (!o.resume) return history;
  try {
    std::ifstream in(std::filesystem::path(o.out_dir) / "summary.json");
    if (in) {
      const auto old = nlohmann::json::parse(in);
      for (const char* key : {"recoveries", "resumes"})
        if (old.contains(key)) history[key] = old[key];
    }
  } catch (const std::exception& e) {
    log->warn("the earlier summary.json does not parse ({}); its history is not carried over", e.what());
  }
  return history;
}

// The wall time split, steps and coupling iterations so far.
void fill_times(fsi::RunReport& report, Clock::time_point start, const Servers& servers,
                const fsi::coupling::Coupler* coupler, const fsi::coupling::RunOutcome& outcome) {
  const auto& solid = servers.solid;
  const auto& fluid = servers.fluid;
  auto& w = report.data()["wall_time"];
  w["total"] = std::chrono::duration<double>(Clock::now() - start).count();
  if (solid) w["solid_compute"] = solid->times().compute, w["solid_messaging"] = solid->times().messaging();
  if (fluid) w["fluid_compute"] = fluid->times().compute, w["fluid_messaging"] = fluid->times().messaging();
  if (coupler) w["coupler_mapping_relaxation"] = coupler->times().coupler;
  if (coupler && coupler->times().checkpoint > 0) w["checkpoint"] = coupler->times().checkpoint;
  if (solid && !solid->timings().empty()) w["solid_breakdown"] = solid->timings();
  if (fluid && !fluid->timings().empty()) w["fluid_breakdown"] = fluid->timings();
  if (solid && !solid->diagnostics().empty()) report.data()["solid_diagnostics"] = solid->diagnostics();
  if (fluid && !fluid->diagnostics().empty()) report.data()["fluid_diagnostics"] = fluid->diagnostics();
  report.data()["steps"] = outcome.steps;
  report.data()["coupling_iterations"] = outcome.iterations;
}

// Connects, runs the scene (summary.json refreshed every 2 s of accepted steps) and fills
// the wall times; a failure of either is the outcome's, never an exception.
void run_coupled(const Options& o, const fsi::Scene& scene, fsi::RunReport& report, Servers& servers,
                 fsi::coupling::RunOutcome& outcome, Clock::time_point start, const Logger& log) {
  try {
    connect_servers(o, servers, report, log);
    fsi::coupling::Coupler coupler(*servers.solid, *servers.fluid, scene, o.out_dir);
    coupler.set_resume(o.resume, o.fresh_start);
    auto last_write = Clock::now();
    coupler.on_step = [&](const fsi::coupling::RunOutcome& step) {
      outcome.steps = step.steps;
      outcome.iterations = step.iterations;
      if (Clock::now() - last_write > std::chrono::seconds(2)) {
        fill_times(report, start, servers, &coupler, outcome);
        report.write();
        last_write = Clock::now();
      }
    };
    outcome = coupler.run(report);
    fill_times(report, start, servers, &coupler, outcome);
  } catch (const std::exception& e) {
    outcome.status = "failed";
    outcome.reason = e.what();
    fill_times(report, start, servers, nullptr, outcome);
  }
}

// The process that started the coupler (fsi run) ended while the run had not: the servers it
// started ended with it (their parent-death signal), and so may the coupler (the same signal). A
// server lost now is not a failure of its own: the run was stopped with its launcher. The outcome
// says so (interrupted, no lost server), whatever the coupler noticed first.
void launcher_gone(pid_t parent, fsi::coupling::RunOutcome& outcome) {
  if (parent <= 1 || getppid() == parent || outcome.status == "completed" || outcome.status == "diverged") return;
  outcome.status = "interrupted";
  outcome.reason = fmt::format(
      "the launcher (pid {}) ended at step {} (stopped or killed); the servers it started ended with it, the run "
      "with them",
      parent, outcome.steps + 1);
}

// The final summary.json: the resume, a lost server, the status. A server that died or
// stopped answering with --recoverable: the survivor is left running and the launcher told
// which one to restart (returns 75); else returns -1.
int write_summary(const Options& o, fsi::RunReport& report, const Servers& servers,
                  const fsi::coupling::RunOutcome& outcome, Clock::time_point start, const Logger& log) {
  if (outcome.resumed_from >= 0) {
    auto& resumes = report.data()["resumes"];
    if (!resumes.is_array()) resumes = nlohmann::json::array();
    resumes.push_back({{"from_step", outcome.resumed_from}});
  }
  std::string lost, cause;
  if (servers.solid && !servers.solid->client().failure().empty())
    lost = "solid_server", cause = servers.solid->client().failure();
  if (servers.fluid && !servers.fluid->client().failure().empty())
    lost = "fluid_server", cause = servers.fluid->client().failure();
  if (outcome.status == "failed" && !lost.empty()) {
    const double elapsed = std::chrono::duration<double>(Clock::now() - start).count();
    report.data()["lost_peer"] = {{"process", lost},
                                  {"cause", cause == "died"      ? "died"
                                            : cause == "timeout" ? "no answer (timeout)"
                                                                 : cause},
                                  {"step", outcome.steps + 1},
                                  {"wall_seconds", report.data().value("wall_time_earlier_segments", 0.0) + elapsed}};
    if (o.recoverable) {
      report.set_status("failed", outcome.reason + " (the launcher will try to recover)");
      try {
        report.write();
      } catch (const std::exception& e) {
        log->error("{}", e.what());
        return fsi::coupling::RunOutcome::kExitWriteFailed;
      }
      log->error("{}: {}", lost, outcome.reason);
      return 75;
    }
  }
  report.set_status(outcome.status, outcome.reason);
  try {
    report.write();
  } catch (const std::exception& e) {  // a full disk: the status goes to stderr instead
    log->error("{}; the run's status is not in it: {}: {}", e.what(), outcome.status, outcome.reason);
    return -2;
  }
  return -1;
}

}  // namespace

int main(int argc, char** argv) {
  fsi::init_process();
  // 1. Parse options.
  Options o;
  if (const int code = parse_options(argc, argv, o); code >= 0) return code;
  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);
  auto log = fsi::logger("coupler");
  const pid_t parent = getppid();  // fsi run, when it started the coupler

  // 2. Load the scene; the report exists from here on, whatever happens.
  std::unique_ptr<fsi::Scene> scene;
  try {
    scene = std::make_unique<fsi::Scene>(fsi::Scene::load(o.scene_path, o.overrides));
  } catch (const std::exception& e) {
    log->error("{}", e.what());
    return 1;
  }
  try {
    if (!o.out_ready)
      fsi::prepare_output_dir(o.out_dir, o.resume  ? fsi::OutputMode::Resume
                                         : o.force ? fsi::OutputMode::Force
                                                   : fsi::OutputMode::Fresh);
  } catch (const std::exception& e) {
    log->error("{}", e.what());
    return 1;
  }
  const nlohmann::json history = earlier_history(o, log);
  fsi::RunReport report(o.out_dir, *scene, "coupler");
  for (const auto& [key, value] : history.items()) report.data()[key] = value;
  const auto start = Clock::now();
  Servers servers;
  fsi::coupling::RunOutcome outcome;

  // 3. Connect (handshake), run, write the summary, stop the servers.
  run_coupled(o, *scene, report, servers, outcome, start, log);
  launcher_gone(parent, outcome);
  const int code = write_summary(o, report, servers, outcome, start, log);
  if (code >= 0) return code;
  if (code == -2) outcome.write_failed = true;
  stop_servers(servers, outcome.status, log);
  if (outcome.status == "completed")
    log->info("completed {} steps, {} coupling iterations; results in {}", outcome.steps, outcome.iterations,
              o.out_dir);
  else
    log->error("{}: {}", outcome.status, outcome.reason);
  for (const auto& [side, data] : {std::pair{"solid", report.data().value("solid_diagnostics", nlohmann::json())},
                                   std::pair{"fluid", report.data().value("fluid_diagnostics", nlohmann::json())}}) {
    std::string text;
    for (const auto& [key, value] : data.items())
      text += fmt::format("{}{} {:.6g}", text.empty() ? "" : ", ", key, value.get<double>());
    if (!text.empty()) log->info("{} diagnostics: {}", side, text);
  }
  return outcome.exit_code();
}
