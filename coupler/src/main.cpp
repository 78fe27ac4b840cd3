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

#include <CLI/CLI.hpp>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include "fsi/common/log.hpp"
#include "fsi/common/version.hpp"
#include "fsi/common/process.hpp"
#include "fsi/common/run_report.hpp"
#include "fsi/coupling/coupler.hpp"
#include "fsi/protocol/client.hpp"
#include "fsi/protocol/remote.hpp"
#include "fsi/transport/transport.hpp"

namespace {
extern "C" void on_signal(int) { fsi::coupling::Coupler::interrupt_flag() = true; }
}  // namespace

int main(int argc, char** argv) {
  fsi::init_process();
  // 1. Parse options.
  CLI::App app{"FSI coupler"};
  std::string scene_path, solid_endpoint, fluid_endpoint, out_dir = "out";
  std::vector<std::string> overrides;
  double timeout = 600, connect_timeout = 20;
  bool resume = false, force = false, recoverable = false, fresh_start = false, out_ready = false;
  std::string curve_keys, generate_keys;
  app.set_version_flag("--version", fsi::version_line("coupler") + "\nprotocol fsi.v1, version " +
                                        std::to_string(fsi::protocol::kProtocolVersion));
  app.add_option("scene", scene_path, "scene file (configs/*.yaml)")->required();
  app.add_option("--solid", solid_endpoint, "solid server endpoint, e.g. tcp://127.0.0.1:5555")
      ->required();
  app.add_option("--fluid", fluid_endpoint, "fluid server endpoint, e.g. tcp://127.0.0.1:5556")
      ->required();
  app.add_option("--out", out_dir, "output folder");
  app.add_option("--set", overrides, "override a scene key: dotted.key=value");
  app.add_option("--timeout", timeout,
                 "seconds to wait for any reply (a dead peer is detected at once)");
  app.add_option("--connect-timeout", connect_timeout, "seconds to wait for the handshake");
  app.add_flag("--resume", resume, "continue the run in --out from its newest complete checkpoint");
  app.add_flag("--force", force, "replace the results of an earlier run in --out");
  app.add_flag(
      "--recoverable", recoverable,
      "exit with code 75 (instead of 1) when a server dies or stops answering, so that the "
      "launcher can restart it and resume (fsi run --recover)");
  app.add_flag("--resume-or-restart", fresh_start,
               "with --resume: start again from step 0 when there is no checkpoint yet");
  app.add_flag("--out-ready", out_ready, "the launcher has prepared --out")->group("");
  app.add_option("--curve-keys", curve_keys,
                 "encrypt and authenticate with ZeroMQ CURVE: the folder made by `fsi keys DIR` "
                 "(coupler.key_secret, "
                 "server.key)");
  app.add_option("--generate-keys", generate_keys,
                 "write a new CURVE key folder and exit (what `fsi keys` runs)")
      ->group("");
  // `coupler --generate-keys DIR` needs no scene.
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
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : 1;
  }
  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);
  auto log = fsi::logger("coupler");

  // 2. Load the scene; the report exists from here on, whatever happens.
  std::unique_ptr<fsi::Scene> scene;
  try {
    scene = std::make_unique<fsi::Scene>(fsi::Scene::load(scene_path, overrides));
  } catch (const std::exception& e) {
    log->error("{}", e.what());
    return 1;
  }
  try {
    if (!out_ready)
      fsi::prepare_output_dir(out_dir, resume  ? fsi::OutputMode::Resume
                                       : force ? fsi::OutputMode::Force
                                               : fsi::OutputMode::Fresh);
  } catch (const std::exception& e) {
    log->error("{}", e.what());
    return 1;
  }
  // A resumed run keeps the history of its earlier segments (resumes, recoveries).
  nlohmann::json history = nlohmann::json::object();
  if (resume) {
    try {
      std::ifstream in(std::filesystem::path(out_dir) / "summary.json");
      if (in) {
        const auto old = nlohmann::json::parse(in);
        for (const char* key : {"recoveries", "resumes"})
          if (old.contains(key)) history[key] = old[key];
      }
    } catch (const std::exception& e) {
      log->warn("the earlier summary.json does not parse ({}); its history is not carried over",
                e.what());
    }
  }
  fsi::RunReport report(out_dir, *scene, "coupler");
  for (const auto& [key, value] : history.items()) report.data()[key] = value;
  const auto start = std::chrono::steady_clock::now();
  std::unique_ptr<fsi::protocol::RemoteSolid> solid;
  std::unique_ptr<fsi::protocol::RemoteFluid> fluid;
  fsi::coupling::RunOutcome outcome;
  auto fill_times = [&](const fsi::coupling::Coupler* coupler) {
    auto& w = report.data()["wall_time"];
    w["total"] = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (solid)
      w["solid_compute"] = solid->times().compute,
      w["solid_messaging"] = solid->times().messaging();
    if (fluid)
      w["fluid_compute"] = fluid->times().compute,
      w["fluid_messaging"] = fluid->times().messaging();
    if (coupler) w["coupler_mapping_relaxation"] = coupler->times().coupler;
    if (coupler && coupler->times().checkpoint > 0) w["checkpoint"] = coupler->times().checkpoint;
    if (solid && !solid->timings().empty()) w["solid_breakdown"] = solid->timings();
    if (fluid && !fluid->timings().empty()) w["fluid_breakdown"] = fluid->timings();
    report.data()["steps"] = outcome.steps;
    report.data()["coupling_iterations"] = outcome.iterations;
  };

  // 3. Connect (handshake), run, stop the servers.
  try {
    const auto connect = std::chrono::milliseconds(static_cast<long>(connect_timeout * 1000));
    const auto keys = curve_keys.empty() ? fsi::transport::CurveKeys{}
                                         : fsi::transport::load_curve_keys(curve_keys, "coupler");
    const auto wait = std::chrono::milliseconds(static_cast<long>(timeout * 1000));
    solid = std::make_unique<fsi::protocol::RemoteSolid>(
        std::make_unique<fsi::protocol::ProtocolClient>(solid_endpoint, "solid server", connect,
                                                        keys));
    fluid = std::make_unique<fsi::protocol::RemoteFluid>(
        std::make_unique<fsi::protocol::ProtocolClient>(fluid_endpoint, "fluid server", connect,
                                                        keys));
    solid->client().set_timeout(wait);
    fluid->client().set_timeout(wait);
    log->info("connected: solid '{}' at {}, fluid '{}' at {}", solid->name(), solid_endpoint,
              fluid->name(), fluid_endpoint);
    report.data()["servers"] = {{"solid", {{"name", solid->name()}, {"endpoint", solid_endpoint}}},
                                {"fluid", {{"name", fluid->name()}, {"endpoint", fluid_endpoint}}}};
    fsi::coupling::Coupler coupler(*solid, *fluid, *scene, out_dir);
    coupler.set_resume(resume, fresh_start);
    auto last_write = std::chrono::steady_clock::now();
    coupler.on_step = [&](const fsi::coupling::RunOutcome& o) {
      outcome.steps = o.steps;
      outcome.iterations = o.iterations;
      if (std::chrono::steady_clock::now() - last_write > std::chrono::seconds(2)) {
        fill_times(&coupler);
        report.write();
        last_write = std::chrono::steady_clock::now();
      }
    };
    outcome = coupler.run(report);
    fill_times(&coupler);
  } catch (const std::exception& e) {
    outcome.status = "failed";
    outcome.reason = e.what();
    fill_times(nullptr);
  }
  if (outcome.resumed_from >= 0) {
    auto& resumes = report.data()["resumes"];
    if (!resumes.is_array()) resumes = nlohmann::json::array();
    resumes.push_back({{"from_step", outcome.resumed_from}});
  }
  // A server that died or stopped answering: with --recoverable, leave the survivor running
  // and tell the launcher which one to restart.
  std::string lost, cause;
  if (solid && !solid->client().failure().empty())
    lost = "solid_server", cause = solid->client().failure();
  if (fluid && !fluid->client().failure().empty())
    lost = "fluid_server", cause = fluid->client().failure();
  if (outcome.status == "failed" && !lost.empty()) {
    const double elapsed =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    report.data()["lost_peer"] = {
        {"process", lost},
        {"cause", cause == "died"      ? "died"
                  : cause == "timeout" ? "no answer (timeout)"
                                       : cause},
        {"step", outcome.steps + 1},
        {"wall_seconds", report.data().value("wall_time_earlier_segments", 0.0) + elapsed}};
    if (recoverable) {
      report.set_status("failed", outcome.reason + " (the launcher will try to recover)");
      report.write();
      log->error("{}: {}", lost, outcome.reason);
      return 75;
    }
  }
  report.set_status(outcome.status, outcome.reason);
  report.write();
  try {
    if (solid) solid->stop(outcome.status);
  } catch (const std::exception& e) {
    log->warn("could not stop the solid server: {}", e.what());
  }
  try {
    if (fluid) fluid->stop(outcome.status);
  } catch (const std::exception& e) {
    log->warn("could not stop the fluid server: {}", e.what());
  }
  if (outcome.status == "completed")
    log->info("completed {} steps, {} coupling iterations; results in {}", outcome.steps,
              outcome.iterations, out_dir);
  else
    log->error("{}: {}", outcome.status, outcome.reason);
  return outcome.exit_code();
}
