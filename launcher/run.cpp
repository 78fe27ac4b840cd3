#include "run.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <filesystem>

#include "check.hpp"
#include "final_values.hpp"
#include "fsi/common/log.hpp"
#include "fsi/common/run_report.hpp"
#include "fsi/common/scene_reader.hpp"
#include "fsi/common/standalone.hpp"
#include "fsi/coupling/settings.hpp"
#include "processes.hpp"
#include "python_tools.hpp"
#include "recovery.hpp"
#include "resume.hpp"
#include "run_folder.hpp"

namespace fs = std::filesystem;

namespace fsi::launcher {
namespace {

// One solver alone (a scene without `coupling`).
int run_single(const RunOptions& o, const fsi::Scene& scene, const std::vector<std::string>& sets) {
  auto log = fsi::logger("fsi");
  const bool has_solid = scene.has("solid"), has_fluid = scene.has("fluid");
  Ending e;
  Child main;
  try {
    if (o.resume) throw fsi::ConfigError("--resume: only coupled runs write checkpoints");
    if (has_solid == has_fluid)
      throw fsi::ConfigError(o.scene_path + ": a scene without 'coupling' must have exactly one of 'solid' or 'fluid'");
    const std::string server = has_solid ? "solid_server" : "fluid_server";
    std::vector<std::string> argv{(self_dir() / server).string(), "--standalone", o.scene_path, "--out", o.out_dir};
    argv.insert(argv.end(), sets.begin(), sets.end());
    if (has_fluid) {
      const auto mpi = fluid_mpi_launcher(scene);
      argv.insert(argv.begin(), mpi.begin(), mpi.end());
      if (!mpi.empty()) log->info("fluid on {} MPI ranks: {}", mpi[2], fmt::join(mpi, " "));
    }
    log->info("scene '{}': {} alone", o.scene_path, server);
    main = spawn(server, argv, "");
    wait_forwarding_signals(main, std::chrono::milliseconds(20), false);
    e.code = main.status;
    if (e.code > 128 && e.code != 130) {
      e.status = "failed";
      e.reason = fmt::format("{} was killed by {} ({})", server, signal_name(e.code - 128), e.code - 128);
      e.code = 1;
    }
  } catch (const std::exception& ex) {
    log->error("{}", ex.what());
    e = {1, "failed", ex.what()};
  }
  stop(main, std::chrono::seconds(2));
  if (g_signal && e.code != 0 && e.code != 2 && e.code != 130 && e.status.empty()) e.code = 130;
  finalize_summary(o.out_dir, scene, e.status.empty() ? (e.code == 130 ? "interrupted" : "failed") : e.status,
                   e.reason.empty() ? "the run ended without a final summary" : e.reason, e.status.empty());
  return e.code;
}

// Coupled: two servers and the coupler; with --recover, a server that dies or stops
// answering is started again with the same command and address and the run resumes
// from the last checkpoint.
int run_coupled(const RunOptions& o, const fsi::Scene& scene, const std::vector<std::string>& sets) {
  auto log = fsi::logger("fsi");
  const fs::path out(o.out_dir), ports = out / ".ports";
  CoupledProcesses p;
  Ending e;
  try {
    if (!scene.has("solid") || !scene.has("fluid"))
      throw fsi::ConfigError(o.scene_path + ": a coupled scene needs 'solid' and 'fluid'");
    const int every = fsi::read_time(scene).checkpoint_every;
    const int recover = o.recover < 0 ? (every > 0 ? 3 : 0) : o.recover;
    if (recover > 0 && every == 0)
      log->warn("--recover without checkpoints (time.checkpoint_every: 0): a recovered run starts again from step 0");
    start_servers(o, ports, p, fluid_mpi_launcher(scene));
    e = run_with_recovery(o, p, recover, sets);
    after_coupler(out, every, p, e);
  } catch (const std::exception& ex) {
    log->error("{}", ex.what());
    e = {g_signal ? 130 : 1, g_signal ? "interrupted" : "failed", ex.what()};
  }
  stop_all({&p.coupler, &p.children[0], &p.children[1]},
           e.code == 0 || e.code == 2 || e.code == 130 ? std::chrono::seconds(3) : std::chrono::seconds(1));
  fs::remove_all(ports);
  if (e.status.empty() && e.code == kExitWriteFailed)
    e.reason = "the coupler could not write its output (a full disk or an I/O error; its message names the file)";
  else if (e.status.empty() && e.code != 0 && e.code != 1 && e.code != 2 && e.code != 130)
    e = {1, "failed", fmt::format("the coupler exited with code {}", e.code)};
  finalize_summary(out, scene, e.status.empty() ? "failed" : e.status,
                   e.reason.empty() ? "the coupler ended without a final summary" : e.reason, e.status.empty());
  if (e.code != 0 && e.code != 2) say_how_to_resume(o, out);
  return e.code;
}

// The end of every run that got as far as starting: the final values and statistics of its
// probes (stdout, summary.json), then with --plot its pictures (fsi plot).
int after_run(const RunOptions& o, int code) {
  fsi::launcher::report_final_values(o.out_dir);
  if (o.plot && code != 130) {
    const int plotted = fsi::launcher::plot_folder(o.out_dir, python_interpreter(), self_dir());
    if (plotted != 0) fsi::logger("fsi")->warn("fsi plot {} exited with {}", o.out_dir, plotted);
  }
  return code;
}

}  // namespace

int run(const RunOptions& given) {
  RunOptions o = given;
  if (o.resume) {
    const auto overrides = prepare_resume(given);
    if (!overrides) return 0;
    o.overrides = *overrides;
    recall_commands(o, given);
  }
  // --initial-state DIR: the fluid starts from the fields of DIR's checkpoint (fluid.initial_state).
  if (!o.initial_state.empty())
    o.overrides.push_back(
        "fluid.initial_state=" +
        fs::absolute(fork_checkpoint(o.initial_state, "--initial-state").dir / "fluid.state").string());
  // Every key of every section against the scene schema, before anything starts (fsi check);
  // the sections an external solver reads are its own business.
  std::vector<std::string> external;
  if (!o.solid_command.empty()) external.push_back("solid");
  if (!o.fluid_command.empty()) external.push_back("fluid");
  std::string problems;
  if (!fsi::launcher::check_before_run(o.scene_path, o.overrides, external, problems))
    return 1;  // nothing started, nothing written (the problems are printed): the corrected scene
               // runs into the same --out without --force
  const auto scene = fsi::Scene::load(o.scene_path, o.overrides);  // fails early on a bad file
  const bool coupled = scene.has("coupling");
  const fs::path out(o.out_dir);
  fsi::prepare_output_dir(out, o.resume  ? fsi::OutputMode::Resume
                               : o.force ? fsi::OutputMode::Force
                                         : fsi::OutputMode::Fresh);
  if (!o.from.empty()) {
    if (!coupled) throw fsi::ConfigError("--from: only coupled runs have checkpoints to start from");
    prepare_fork(o.from, out);
  }
  if (coupled) {
    // From the start the folder is a run folder: summary.json (running) until the coupler's
    // first, and the commands a --resume starts again.
    if (!fs::exists(out / "summary.json")) {
      fsi::RunReport report(out, scene, "fsi");
      report.write();
    }
    remember_commands(o);
  }
  std::vector<std::string> sets;
  for (const auto& ov : o.overrides) sets.insert(sets.end(), {"--set", ov});
  const int code = coupled ? run_coupled(o, scene, sets) : run_single(o, scene, sets);
  return after_run(o, code);
}

}  // namespace fsi::launcher
