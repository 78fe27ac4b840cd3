// fsi: one command that runs a scene, starting exactly the processes it needs on free
// loopback ports and stopping them all at the end, on failure, or on Ctrl-C.
//
// Sample runs:
//   fsi run configs/sdof_model.yaml --out runs/sdof
//   fsi run configs/sdof_model.yaml --out runs/sdof_g100 --set coupling.gamma_n1=100
//   fsi run configs/csm1.yaml --out runs/csm1               # solid alone: one process
//   fsi run configs/sdof_model.yaml --out runs/py --solid-command "python3 python/sdof_solid.py"
//
// A scene with a `coupling` section runs solid_server + fluid_server + coupler; a scene
// with only `solid` (or only `fluid`) runs that server alone with --standalone.
// Exit codes: 0 completed, 2 diverged, 1 failed (bad input or options, a dead peer that could
// not be recovered, a crashed coupler), 130 interrupted (SIGINT / SIGTERM). Every way a run
// ends leaves summary.json with its final status.
//
// This file is the command line and its dispatch. The run: run.cpp (a scene checked, then one
// solver alone or the coupled processes), processes.cpp (starting and stopping them, signals),
// recovery.cpp (a coupled run's servers and their recovery), resume.cpp (--resume, extension,
// --from), run_folder.cpp (summary.json, the newest checkpoint); check.cpp (fsi check),
// final_values.cpp (the final values at the end), python_tools.cpp (fsi plot, study, list).
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <csignal>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <string>
#include <utility>
#include <vector>

#include "check.hpp"
#include "fsi/common/log.hpp"
#include "fsi/common/scene_schema.hpp"
#include "fsi/common/standalone.hpp"
#include "fsi/common/version.hpp"
#include "fsi/common/write_check.hpp"
#include "fsi/coupling/settings.hpp"
#include "fsi/models/fluid_factory.hpp"
#include "fsi/models/solid_factory.hpp"
#include "processes.hpp"
#include "python_tools.hpp"
#include "run.hpp"

namespace fs = std::filesystem;

namespace {

using fsi::launcher::python_interpreter;
using fsi::launcher::RunOptions;
using fsi::launcher::self_dir;
using fsi::launcher::study_tool;

// ---- The command line: fsi run | keys | check | study.

CLI::App* add_run_command(CLI::App& app, RunOptions& o) {
  auto* run_cmd = app.add_subcommand("run", "run one scene, starting only the processes it needs");
  run_cmd->add_option("scene", o.scene_path, "scene file (configs/*.yaml)")->required()->check(CLI::ExistingFile);
  run_cmd->add_option("--out", o.out_dir,
                      "output folder (summary.json, probes.csv, iterations.csv, logs, vtk/, checkpoints/); "
                      "default: runs/<scene file name without .yaml>; refused when not empty, unless --resume or "
                      "--force");
  run_cmd->add_option("--set", o.overrides, "override any scene key: dotted.key=value (repeatable)");
  run_cmd->add_option("--solid-command", o.solid_command,
                      "start this external solid instead of solid_server (gets --bind and --port-file)");
  run_cmd->add_option("--fluid-command", o.fluid_command, "start this external fluid instead of fluid_server");
  run_cmd
      ->add_option("--timeout", o.timeout,
                   "seconds the coupler waits for any single reply (a server that does not answer within it "
                   "counts as failed; a dead one is noticed at once)")
      ->capture_default_str();
  run_cmd
      ->add_option("--start-timeout", o.start_timeout,
                   "seconds a server may take to start (write its port file); the coupler's first request "
                   "(Hello) waits half of it")
      ->check(CLI::Range(2, 86400))
      ->capture_default_str();
  run_cmd->add_flag("--resume", o.resume, "continue the run in --out from its newest complete checkpoint");
  run_cmd->add_flag("--force", o.force, "replace the results of an earlier run in --out");
  run_cmd->add_flag("--plot", o.plot, "at the end, draw the run's pictures into --out (as fsi plot OUT)");
  run_cmd->add_option("--from", o.from,
                      "start from a checkpoint of another run (its folder: the newest checkpoint; or one "
                      "checkpoints/step_N folder) with this scene and --set changes, into a new --out (the "
                      "original is not touched; summary.json lists the changed keys)");
  run_cmd->add_option("--initial-state", o.initial_state,
                      "start the fluid from the velocity and pressure of another run's checkpoint (its folder: the "
                      "newest; or one checkpoints/step_N folder), interpolated onto this run's mesh (another mesh or "
                      "element is fine); sets fluid.initial_state");
  run_cmd->add_option("--recover", o.recover,
                      "restart a server that dies or stops answering up to N times, resuming from the last "
                      "checkpoint (default: 3 when time.checkpoint_every > 0, else 0)");
  run_cmd
      ->add_option("--curve-keys", o.curve_keys,
                   "encrypt and authenticate the connections with ZeroMQ CURVE, keys from `fsi keys DIR`")
      ->check(CLI::ExistingDirectory);
  return run_cmd;
}

struct CheckOptions {
  std::string file;
  std::vector<std::string> overrides;
  std::vector<std::pair<std::string, std::string>> placed;
  bool reference = false;
  bool json = false;
  bool cases = false;
  std::string solid_command, fluid_command;  // external solvers: their sections are not checked
};

CLI::App* add_check_command(CLI::App& app, CheckOptions& c) {
  auto* check_cmd =
      app.add_subcommand("check",
                         "check a scene (or a study's scene with its fixed and varied keys) against the scene schema, "
                         "without meshing or starting a solver: fsi check SCENE|STUDY [--set key=value ...]");
  check_cmd->add_option("file", c.file, "scene (configs/*.yaml) or study (studies/*.yaml)");
  check_cmd->add_option("--set", c.overrides, "override any scene key: dotted.key=value (repeatable)");
  check_cmd->add_option("--set-at", c.placed,
                        "as --set, with the place the value was written, named in the problems: --set-at "
                        "key=value file:line:col (the study tool checks a study's cases this way)");
  check_cmd->add_flag("--json", c.json, "a scene's problems as one JSON object on stdout");
  check_cmd->add_flag("--cases", c.cases,
                      "read a JSON list of cases from stdin, each a list of [key=value, file:line:col] on top of "
                      "the other overrides, and print a JSON list of their results (the study tool)");
  check_cmd->add_option("--solid-command", c.solid_command,
                        "the scene runs with this external solid (as fsi run --solid-command): its solid section is "
                        "the external solid's, not checked here");
  check_cmd->add_option("--fluid-command", c.fluid_command,
                        "the scene runs with this external fluid: its fluid section is not checked here");
  check_cmd->add_flag("--reference", c.reference,
                      "print the scene reference (Markdown, docs/scene-reference.md) from the schema");
  return check_cmd;
}

int check(const CheckOptions& c) {
  if (c.reference) {
    std::cout << fsi::schema::reference_markdown();
    return 0;
  }
  if (c.file.empty()) {
    std::cerr << "fsi check: give a scene or study file (or --reference)\n";
    return 1;
  }
  if (fsi::launcher::is_study_file(c.file)) {  // the study tool reads studies, and checks each case here
    std::vector<std::string> args{c.file};
    for (const auto& o : c.overrides) args.insert(args.end(), {"--set", o});
    return study_tool("check", args);
  }
  if (c.cases) return fsi::launcher::check_cases(c.file, c.overrides, c.placed, std::cin);
  std::vector<std::string> external;
  if (!c.solid_command.empty()) external.push_back("solid");
  if (!c.fluid_command.empty()) external.push_back("fluid");
  return fsi::launcher::check_file(c.file, c.overrides, c.placed, c.json, external);
}

// `fsi keys DIR`: the coupler writes the key folder. Replaces this process; returns only on failure.
int keys(std::string keys_dir) {
  if (fs::exists(fs::path(keys_dir) / "server.key_secret") || fs::exists(fs::path(keys_dir) / "coupler.key_secret")) {
    fsi::logger("fsi")->error("{} already holds keys: remove them first or choose another folder", keys_dir);
    return 1;
  }
  const std::string coupler = (self_dir() / "coupler").string();
  std::vector<char*> args{const_cast<char*>(coupler.c_str()), const_cast<char*>("--generate-keys"), keys_dir.data(),
                          nullptr};
  execv(args[0], args.data());
  fsi::logger("fsi")->error("cannot start {}: {}", coupler, std::strerror(errno));
  return 1;
}

// The run options that exclude each other, and the default --out: -1 when fine, else the exit code.
int settle_run_options(RunOptions& o, bool run_parsed) {
  if (run_parsed && o.out_dir.empty()) {
    o.out_dir = (fs::path("runs") / fs::path(o.scene_path).stem()).string();
    fsi::logger("fsi")->info("results in {} (choose the folder with --out)", o.out_dir);
  }
  if (!o.from.empty() && o.resume) {
    fsi::logger("fsi")->error("--from and --resume exclude each other (a forked run is resumed with --resume alone)");
    return 1;
  }
  if (o.resume && o.force) {
    fsi::logger("fsi")->error("--resume and --force exclude each other");
    return 1;
  }
  return -1;
}

}  // namespace

int main(int argc, char** argv) {
  // Every section's keys, each declared beside its reader: `fsi check`, `fsi run`'s check and
  // the reference know them all.
  fsi::coupling::coupling_section();
  fsi::models::solid_section();
  fsi::models::fluid_section();
  CLI::App app{"fsi: partitioned fluid-structure interaction co-simulation"};
  app.require_subcommand(1);
  app.set_version_flag("--version", fsi::version_line("fsi"));
  RunOptions o;
  auto* run_cmd = add_run_command(app, o);
  auto* keys_cmd = app.add_subcommand(
      "keys", "write a new CURVE key folder for servers and coupler that talk beyond loopback (proto/README.md)");
  std::string keys_dir;
  keys_cmd->add_option("folder", keys_dir, "folder to create (server.key[_secret], coupler.key[_secret])")->required();
  CheckOptions check_options;
  auto* check_cmd = add_check_command(app, check_options);
  std::string plot_dir;
  auto* plot_cmd = app.add_subcommand(
      "plot",
      "draw the pictures of a run folder (probe histories with their final statistics; Turek-Hron "
      "FSI1-3 against the reference) or of a study folder (its maps, work-precision, histories), as PNG "
      "files into that folder, with the Python the build found ($FSI_PYTHON overrides it)");
  plot_cmd->add_option("folder", plot_dir, "a run folder (fsi run --out) or a study folder (fsi study --out)")
      ->required()
      ->check(CLI::ExistingDirectory);
  auto* study_cmd =
      app.add_subcommand("study",
                         "run a parameter study: fsi study STUDY.yaml --out DIR [--jobs N] [...] (docs/studies.md; "
                         "every option after the study file goes to the study tool, see fsi study STUDY.yaml --help)");
  study_cmd->allow_extras();
  study_cmd->prefix_command();
  auto* list_cmd = app.add_subcommand(
      "list",
      "the scenes and studies of this checkout: description, solvers, unknowns and the wall time measured "
      "on a reference machine (configs/catalog.json); a study's estimated total: fsi list [--json]");
  list_cmd->allow_extras();
  list_cmd->prefix_command();
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : 1;  // command-line errors exit 1, like every failed run
  }
  if (const int code = settle_run_options(o, run_cmd->parsed()); code >= 0) return code;
  if (study_cmd->parsed()) return study_tool("run", study_cmd->remaining());
  if (list_cmd->parsed()) return study_tool("list", list_cmd->remaining());
  if (check_cmd->parsed()) return check(check_options);
  if (keys_cmd->parsed()) return keys(keys_dir);
  if (plot_cmd->parsed()) return fsi::launcher::plot_folder(plot_dir, python_interpreter(), self_dir());
  std::signal(SIGINT, fsi::launcher::on_signal);
  std::signal(SIGTERM, fsi::launcher::on_signal);
  try {
    return fsi::launcher::run(o);
  } catch (const std::exception& e) {
    fsi::logger("fsi")->error("{}", e.what());
    return fsi::is_write_failure(e.what()) ? fsi::launcher::kExitWriteFailed : 1;
  }
}
