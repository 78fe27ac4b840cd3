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
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <csignal>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <thread>
#include <vector>

#include "check.hpp"
#include "final_values.hpp"
#include "fsi/common/config.hpp"
#include "fsi/common/log.hpp"
#include "fsi/common/run_report.hpp"
#include "fsi/common/scene_reader.hpp"
#include "fsi/common/scene_schema.hpp"
#include "fsi/common/standalone.hpp"
#include "fsi/common/version.hpp"
#include "fsi/common/write_check.hpp"
#include "fsi/coupling/checkpoint.hpp"
#include "fsi/coupling/settings.hpp"
#include "fsi/models/fluid_factory.hpp"
#include "fsi/models/solid_factory.hpp"

namespace fs = std::filesystem;

namespace {

// Launcher limits: a server must write its port file within --start-timeout (60 s) of starting and answer
// the coupler's Hello within half of it (generous: a loaded machine, a Python solver importing its modules); at
// the end each process gets 3 s to exit after Stop (1 s when the run failed: a server that never answered got no
// Stop it could obey), then SIGTERM, then SIGKILL 0.5 s later.

volatile std::sig_atomic_t g_signal = 0;
extern "C" void on_signal(int sig) { g_signal = sig; }

struct Child {
  std::string name;
  pid_t pid = -1;
  fs::path log;
  int status = -1;  // exit code once reaped
  bool alive() const { return pid > 0 && status < 0; }
};

// Starts `argv` (or `/bin/sh -c shell_command`) with stdout/stderr to `log` (empty = inherit).
Child spawn(const std::string& name, const std::vector<std::string>& argv, const fs::path& log,
            const std::string& shell_command = "") {
  Child c{name, -1, log};
  const pid_t pid = fork();
  if (pid < 0) throw std::runtime_error("fork failed for " + name);
  if (pid == 0) {
    prctl(PR_SET_PDEATHSIG, SIGTERM);  // never outlive the launcher
    // Two or three solver processes share the cores: no busy-waiting OpenMP threads and
    // one BLAS thread each, unless the user says otherwise (TOOLCHAIN.md, docs/fluid.md).
    setenv("OMP_WAIT_POLICY", "passive", 0);
    setenv("OPENBLAS_NUM_THREADS", "1", 0);
    setpgid(0, 0);  // own process group: Ctrl-C goes through the launcher
    if (!log.empty()) {
      // Appended: a resumed or recovered run keeps its earlier segments' logs (a fresh run's
      // folder has none, --force removes them).
      FILE* f = std::fopen(log.c_str(), "a");
      if (f) {
        dup2(fileno(f), STDOUT_FILENO);
        dup2(fileno(f), STDERR_FILENO);
      }
    }
    if (!shell_command.empty()) {
      execl("/bin/sh", "sh", "-c", shell_command.c_str(), static_cast<char*>(nullptr));
    } else {
      std::vector<char*> args;
      for (const auto& a : argv) args.push_back(const_cast<char*>(a.c_str()));
      args.push_back(nullptr);
      execv(args[0], args.data());
    }
    std::fprintf(stderr, "cannot start %s: %s\n", name.c_str(), std::strerror(errno));
    _exit(127);
  }
  c.pid = pid;
  return c;
}

void reap(Child& c, bool block) {
  if (!c.alive()) return;
  int status = 0;
  const pid_t r = waitpid(c.pid, &status, block ? 0 : WNOHANG);
  if (r == c.pid) c.status = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

// Stops children together: waits up to `grace` for them to exit by themselves, then
// SIGTERM to all, up to `term_wait`, then SIGKILL. Always reaps.
void stop_all(std::vector<Child*> children, std::chrono::milliseconds grace,
              std::chrono::milliseconds term_wait = std::chrono::milliseconds(500)) {
  const auto wait_all = [&](std::chrono::milliseconds d) {
    const auto end = std::chrono::steady_clock::now() + d;
    while (std::chrono::steady_clock::now() < end) {
      bool any = false;
      for (auto* c : children) {
        reap(*c, false);
        any = any || c->alive();
      }
      if (!any) return;
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
  };
  wait_all(grace);
  for (auto* c : children)
    if (c->alive()) kill(-c->pid, SIGTERM), kill(c->pid, SIGTERM);
  wait_all(term_wait);
  for (auto* c : children)
    if (c->alive()) {
      kill(-c->pid, SIGKILL);
      kill(c->pid, SIGKILL);
      reap(*c, true);
    }
}
void stop(Child& c, std::chrono::milliseconds grace) { stop_all({&c}, grace); }

std::string tail(const fs::path& file, int lines) {
  std::ifstream in(file);
  std::vector<std::string> all;
  for (std::string line; std::getline(in, line);) all.push_back(line);
  std::string out;
  for (std::size_t i = all.size() > static_cast<std::size_t>(lines) ? all.size() - lines : 0; i < all.size(); ++i)
    out += "    " + all[i] + "\n";
  return out;
}

// Waits for a server to write its bound endpoint.
std::string wait_for_endpoint(Child& c, const fs::path& port_file, std::chrono::seconds timeout) {
  const auto end = std::chrono::steady_clock::now() + timeout;
  while (std::chrono::steady_clock::now() < end) {
    if (g_signal) throw std::runtime_error("interrupted while starting " + c.name);
    // Complete only with its trailing newline (a writer that is not atomic may be mid-way).
    std::ifstream in(port_file);
    std::string content((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    if (!content.empty() && content.back() == '\n') {
      const std::string endpoint = content.substr(0, content.find('\n'));
      if (!endpoint.empty()) return endpoint;
    }
    reap(c, false);
    if (!c.alive())
      throw std::runtime_error(fmt::format("{} exited with code {} before listening; its log ({}):\n{}", c.name,
                                           c.status, c.log.string(), tail(c.log, 15)));
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  throw std::runtime_error(fmt::format("{} did not report its endpoint within {} s", c.name, timeout.count()));
}

fs::path self_dir() { return fs::read_symlink("/proc/self/exe").parent_path(); }

const char* signal_name(int sig) {
  switch (sig) {
    case SIGINT:
      return "SIGINT";
    case SIGTERM:
      return "SIGTERM";
    case SIGKILL:
      return "SIGKILL";
    case SIGSEGV:
      return "SIGSEGV";
    case SIGABRT:
      return "SIGABRT";
    case SIGBUS:
      return "SIGBUS";
    case SIGFPE:
      return "SIGFPE";
    case SIGHUP:
      return "SIGHUP";
    default:
      return "a signal";
  }
}

nlohmann::json read_json(const fs::path& file) {
  std::ifstream in(file);
  if (!in) return nullptr;
  try {
    return nlohmann::json::parse(in);
  } catch (const std::exception&) {
    return nullptr;
  }
}

// Throws fsi::WriteError naming the file (a full disk); no .tmp is left behind.
void write_json_atomic(const fs::path& file, const nlohmann::json& j) {
  fsi::write_file_atomic(file, j.dump(2) + "\n");
}

// Makes summary.json final when its writer could not: status, reason, and steps equal to
// the rows of probes.csv. Creates it from the scene if the run never wrote one.
void finalize_summary(const fs::path& out, const fsi::Scene& scene, const std::string& status,
                      const std::string& reason, bool only_if_running) {
  nlohmann::json j = read_json(out / "summary.json");
  if (j.is_null() || !j.is_object()) {
    fsi::RunReport report(out, scene, "fsi");
    j = report.data();
  } else if (only_if_running && j.value("status", std::string("running")) != "running") {
    return;
  }
  j["status"] = status;
  j["reason"] = reason;
  j["steps"] = fsi::csv_rows(out / "probes.csv");
  try {
    write_json_atomic(out / "summary.json", j);
  } catch (const std::exception& e) {  // a full disk: the status goes to stderr instead
    fsi::logger("fsi")->error("{}; the run's status is not in it: {}: {}", e.what(), status, reason);
  }
}

// The newest complete checkpoint's manifest (null if none), as the coupler finds it.
nlohmann::json newest_checkpoint(const fs::path& out) {
  const auto c = fsi::coupling::CheckpointStore(out / "checkpoints", 1).newest();
  return c ? c->manifest : nlohmann::json(nullptr);
}

struct Server {
  std::string side;     // "solid" / "fluid"
  std::string command;  // external command ("" = ours)
  std::string endpoint;
  fs::path port_file, log;
  std::string curve_keys;             // CURVE key folder ("" = none)
  std::vector<std::string> mpi = {};  // our server under the MPI launcher (fluid.ranks > 1)
};

// The program on PATH (or a path with a slash, as given); "" if none.
std::string find_program(const std::string& name) {
  if (name.find('/') != std::string::npos) return access(name.c_str(), X_OK) == 0 ? name : "";
  const char* path = std::getenv("PATH");
  std::string dirs = path ? path : "/usr/bin:/bin";
  std::size_t start = 0;
  while (start <= dirs.size()) {
    const std::size_t end = std::min(dirs.find(':', start), dirs.size());
    const fs::path candidate = fs::path(dirs.substr(start, end - start)) / name;
    if (access(candidate.c_str(), X_OK) == 0) return candidate.string();
    start = end + 1;
  }
  return "";
}

// fluid.ranks > 1: the command line that starts fluid_server on that many MPI ranks
// (fluid.mpi: command, hostfile, args); empty for one rank (no MPI launcher at all).
std::vector<std::string> fluid_mpi_launcher(const fsi::Scene& scene) {
  if (!scene.has("fluid.ranks")) return {};
  // fluid.ranks and fluid.mpi are keys of the fem fluid (navier_stokes_keys.cpp).
  const auto& variants = fsi::models::fluid_section().variants;
  const auto fem = std::find_if(variants.begin(), variants.end(), [](const auto& v) { return v.value == "fem"; });
  if (fem == variants.end()) return {};
  const fsi::ConfigSection section = scene.section("fluid");
  const fsi::schema::Reader fluid(section, fem->keys);
  const int ranks = fluid.get<int>("ranks");
  if (ranks <= 1) return {};
  const auto mpi_key =
      std::find_if(fem->keys.begin(), fem->keys.end(), [](const fsi::schema::Key& k) { return k.name == "mpi"; });
  const fsi::schema::Reader mpi(section.child_or_empty("mpi"), mpi_key->children);
  const auto command = mpi.get<std::string>("command");
  const std::string hostfile = mpi.has("hostfile") ? mpi.path("hostfile").string() : "";
  const auto args = mpi.get<std::vector<std::string>>("args");
  const std::string program = find_program(command);
  if (program.empty())
    throw fsi::ConfigError(fmt::format(
        "fluid.ranks: {} needs the MPI launcher '{}' (fluid.mpi.command), which is not on PATH (Debian: apt-get "
        "install openmpi-bin)",
        ranks, command));
  const bool placed = !hostfile.empty() || std::any_of(args.begin(), args.end(), [](const std::string& a) {
    return a == "--oversubscribe" || a == "--host" || a == "-H" || a == "--hostfile" || a == "--machinefile";
  });
  const unsigned cores = std::thread::hardware_concurrency();
  if (!placed && cores > 0 && static_cast<unsigned>(ranks) > cores)
    throw fsi::ConfigError(
        fmt::format("fluid.ranks: {} ranks but this host has {} cores: run on several hosts (fluid.mpi.hostfile) or "
                    "oversubscribe (fluid.mpi.args: [--oversubscribe])",
                    ranks, cores));
  std::vector<std::string> argv{program, "-n", std::to_string(ranks)};
  if (geteuid() == 0) argv.push_back("--allow-run-as-root");
  if (!hostfile.empty()) argv.insert(argv.end(), {"--hostfile", hostfile});
  argv.insert(argv.end(), args.begin(), args.end());
  return argv;
}

Child start_server(Server& s, const fs::path& bin, const std::string& bind, std::chrono::seconds timeout) {
  const std::string server = s.side + "_server";
  fs::remove(s.port_file);
  Child c;
  if (s.command.empty()) {
    std::vector<std::string> argv{(bin / server).string(), "--bind", bind, "--port-file", s.port_file.string()};
    if (!s.curve_keys.empty()) argv.insert(argv.end(), {"--curve-keys", s.curve_keys});
    argv.insert(argv.begin(), s.mpi.begin(), s.mpi.end());
    c = spawn(server, argv, s.log);
  } else {
    std::string shell = fmt::format("exec {} --bind '{}' --port-file '{}'", s.command, bind, s.port_file.string());
    if (!s.curve_keys.empty()) shell += fmt::format(" --curve-keys '{}'", s.curve_keys);
    c = spawn(server + " (external)", {}, s.log, shell);
  }
  try {
    s.endpoint = wait_for_endpoint(c, s.port_file, timeout);
  } catch (...) {
    stop(c, std::chrono::milliseconds(0));
    throw;
  }
  return c;
}

struct RunOptions {
  std::string scene_path, out_dir, solid_command, fluid_command, curve_keys;
  std::string from;           // --from: a run folder (its newest checkpoint) or one checkpoint folder
  std::string initial_state;  // --initial-state: the same, for the fluid's fields only
  std::vector<std::string> overrides;
  double timeout = 600;
  int start_timeout = 60;  // --start-timeout: seconds for a server's port file (its Hello: half of it)
  bool resume = false, force = false;
  bool plot = false;  // --plot: tools/fsi_plot.py on --out at the end
  int recover = -1;   // -1: 3 when checkpoints are on, else 0
};

// --from PATH: the checkpoint folder (PATH itself when it holds a manifest.json, else the
// newest complete one under PATH/checkpoints), checked as the coupler checks it.
fsi::coupling::CheckpointStore::Loaded fork_checkpoint(const std::string& from, const std::string& option = "--from") {
  const fs::path p(from);
  if (fs::exists(p / "manifest.json")) {
    try {
      return fsi::coupling::CheckpointStore::read(p);
    } catch (const std::exception& e) {
      throw fsi::ConfigError(fmt::format("{} '{}': not a complete checkpoint ({})", option, from, e.what()));
    }
  }
  const fs::path dir = p / "checkpoints";
  if (!fs::is_directory(dir))
    throw fsi::ConfigError(
        fmt::format("{} '{}': neither a checkpoint (no manifest.json) nor a run folder with "
                    "checkpoints/ (time.checkpoint_every > 0)",
                    option, from));
  std::vector<std::string> skipped;
  auto found = fsi::coupling::CheckpointStore(dir, 1).newest(&skipped);
  if (!found)
    throw fsi::ConfigError(fmt::format("{} '{}': no complete checkpoint in {}{}", option, from, dir.string(),
                                       skipped.empty() ? std::string() : " (" + skipped.front() + ")"));
  return *found;
}

// Copies the checkpoint into OUT/checkpoints/ and writes OUT/forked_from.json: the coupler
// then continues from it with the scene as given now (changed keys allowed and listed).
void prepare_fork(const std::string& from, const fs::path& out) {
  const auto ckpt = fork_checkpoint(from);
  const nlohmann::json& manifest = ckpt.manifest;
  fs::create_directories(out / "checkpoints");
  fs::copy(ckpt.dir, out / "checkpoints" / ckpt.dir.filename(), fs::copy_options::recursive);
  const nlohmann::json fork = {{"checkpoint", fs::absolute(ckpt.dir).string()},
                               {"step", manifest.value("step", 0)},
                               {"time", manifest.value("time", 0.0)},
                               {"iterations", manifest.value("iterations", 0)},
                               {"scene_file", manifest.value("scene_file", std::string())},
                               {"overrides", manifest.value("overrides", nlohmann::json::array())}};
  std::ofstream(out / "forked_from.json") << fork.dump(2) << "\n";
  fsi::logger("fsi")->info("forking from {} (step {}, t = {})", ckpt.dir.string(), fork["step"].get<int>(),
                           fork["time"].get<double>());
}

// ---- The run: checked, then one solver alone or the coupled processes with their recovery.

// The launcher's last word on a run: its exit code, and the status and reason it writes into
// summary.json (empty: the run's own summary stands).
// The coupler's (and a standalone run's) exit code when an output file could not be written
// (a full disk): EX_IOERR of sysexits.h, passed on by fsi run.
constexpr int kExitWriteFailed = 74;

struct Ending {
  int code = 1;
  std::string status, reason;
};

// Waits for `child`, forwarding a SIGINT/SIGTERM the launcher receives to it once.
void wait_forwarding_signals(Child& child, std::chrono::milliseconds poll, bool warn) {
  bool forwarded = false;
  while (child.alive()) {
    reap(child, false);
    if (g_signal && !forwarded) {
      if (warn) fsi::logger("fsi")->warn("{} received: stopping the coupler", signal_name(g_signal));
      kill(child.pid, g_signal);
      forwarded = true;
    }
    std::this_thread::sleep_for(poll);
  }
}

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

// The processes of a coupled run: the two servers (solid, fluid) and the coupler.
struct CoupledProcesses {
  std::vector<Server> servers;
  std::vector<Child> children = std::vector<Child>(2);  // solid, fluid
  Child coupler;
};

// Starts both servers on free loopback ports.
void start_servers(const RunOptions& o, const fs::path& ports, CoupledProcesses& p,
                   const std::vector<std::string>& fluid_mpi) {
  auto log = fsi::logger("fsi");
  fs::create_directories(ports);
  for (const auto& [side, command] : {std::pair{std::string("solid"), o.solid_command}, {"fluid", o.fluid_command}}) {
    Server s{side, command, "", ports / (side + ".port"), fs::path(o.out_dir) / (side + "_server.log"), o.curve_keys};
    if (side == "fluid" && command.empty()) s.mpi = fluid_mpi;
    const std::size_t i = side == "solid" ? 0 : 1;
    p.children[i] = start_server(s, self_dir(), "tcp://127.0.0.1:*", std::chrono::seconds(o.start_timeout));
    log->info("{} listening on {} (log: {})", p.children[i].name, s.endpoint, s.log.string());
    p.servers.push_back(s);
  }
}

// The coupler's command line (a later attempt resumes, or restarts when there is nothing to resume).
std::vector<std::string> coupler_command(const RunOptions& o, const CoupledProcesses& p, bool resume, int attempts,
                                         int recover, const std::vector<std::string>& sets) {
  std::vector<std::string> argv{(self_dir() / "coupler").string(),
                                o.scene_path,
                                "--solid",
                                p.servers[0].endpoint,
                                "--fluid",
                                p.servers[1].endpoint,
                                "--out",
                                o.out_dir,
                                "--timeout",
                                fmt::format("{}", o.timeout),
                                "--connect-timeout",
                                std::to_string(std::max(1, o.start_timeout / 2)),
                                "--out-ready"};
  if (resume) argv.push_back("--resume");
  if (resume && attempts > 0) argv.push_back("--resume-or-restart");
  if (recover > 0) argv.push_back("--recoverable");
  if (!o.curve_keys.empty()) argv.insert(argv.end(), {"--curve-keys", o.curve_keys});
  argv.insert(argv.end(), sets.begin(), sets.end());
  return argv;
}

// A server died or stopped answering (the coupler exited 75): starts it again with the same
// command and address and records the recovery in summary.json (`lost` = its lost_peer).
void recover_server(const fs::path& out, CoupledProcesses& p, std::size_t i, nlohmann::json summary,
                    const nlohmann::json& lost, int attempt, int recover, std::chrono::seconds port_wait) {
  auto log = fsi::logger("fsi");
  const std::string process = lost.value("process", std::string());
  const auto t0 = std::chrono::steady_clock::now();
  log->warn("{} {} at step {}: restarting it (recovery {} of {})", process, lost.value("cause", std::string("failed")),
            lost.value("step", 0), attempt, recover);
  reap(p.children[i], false);
  if (p.children[i].alive()) {  // stopped or hung: it cannot be trusted any more
    kill(-p.children[i].pid, SIGKILL);
    kill(p.children[i].pid, SIGKILL);
    reap(p.children[i], true);
  }
  p.children[i] = start_server(p.servers[i], self_dir(), p.servers[i].endpoint, port_wait);
  const nlohmann::json checkpoint = newest_checkpoint(out);
  const int from = checkpoint.is_object() ? checkpoint.value("step", 0) : 0;
  const double restart_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const double recompute =
      lost.value("wall_seconds", 0.0) - (checkpoint.is_object() ? checkpoint.value("wall_seconds", 0.0) : 0.0);
  nlohmann::json j = summary.is_object() ? summary : nlohmann::json::object();
  auto& recoveries = j["recoveries"];
  if (!recoveries.is_array()) recoveries = nlohmann::json::array();
  recoveries.push_back({{"step", lost.value("step", 0)},
                        {"process", process},
                        {"cause", lost.value("cause", std::string("unknown"))},
                        {"resumed_from_step", from},
                        {"seconds_lost", std::max(0.0, recompute) + restart_seconds}});
  j.erase("lost_peer");
  write_json_atomic(out / "summary.json", j);
  log->info("{} listening again on {}; resuming from step {}", p.children[i].name, p.servers[i].endpoint, from);
}

// Runs the coupler until it ends; with `recover` > 0, a server that dies or stops answering
// is started again and the run resumes from the last checkpoint, up to `recover` times.
Ending run_with_recovery(const RunOptions& o, CoupledProcesses& p, int recover, const std::vector<std::string>& sets) {
  const fs::path out(o.out_dir);
  Ending e;
  int attempts = 0;
  bool resume = o.resume || !o.from.empty();
  while (true) {
    p.coupler = spawn("coupler", coupler_command(o, p, resume, attempts, recover, sets), "");
    wait_forwarding_signals(p.coupler, std::chrono::milliseconds(10), true);
    e.code = p.coupler.status;
    if (e.code != 75) break;
    // A server died or stopped answering.
    const auto summary = read_json(out / "summary.json");
    const auto lost = summary.is_object() ? summary.value("lost_peer", nlohmann::json::object()) : nlohmann::json();
    const std::string process = lost.value("process", std::string());
    if (g_signal)
      return {130, "interrupted", fmt::format("{} received while recovering {}", signal_name(g_signal), process)};
    if (attempts >= recover)
      return {1, "failed",
              fmt::format("{} {} at step {}; gave up after {} recover{}", process,
                          lost.value("cause", std::string("failed")), lost.value("step", 0), attempts,
                          attempts == 1 ? "y" : "ies")};
    ++attempts;
    recover_server(out, p, process == "solid_server" ? 0 : 1, summary, lost, attempts, recover,
                   std::chrono::seconds(o.start_timeout));
    resume = true;
  }
  return e;
}

// After the coupler: a coupler killed by a signal stops both servers at once; a server that
// failed on its own shows its log.
void after_coupler(CoupledProcesses& p, Ending& e) {
  auto log = fsi::logger("fsi");
  if (e.code > 128 && e.code != 130) {
    // The coupler itself died: say so at once, stop both servers together.
    e.status = "failed";
    e.reason = fmt::format(
        "the coupler was killed by {} ({}); `fsi run ... --resume` continues from the last "
        "checkpoint",
        signal_name(e.code - 128), e.code - 128);
    log->error("{}", e.reason);
    stop_all({&p.children[0], &p.children[1]}, std::chrono::milliseconds(0), std::chrono::milliseconds(400));
    e.code = 1;
  }
  for (auto& c : p.children) {
    reap(c, false);
    if (c.status > 0 && c.status != 130 && e.status.empty())
      log->error("{} exited with code {}; its log ({}):\n{}", c.name, c.status, c.log.string(), tail(c.log, 10));
  }
}

// An interrupted or failed coupled run with a checkpoint: the exact command that continues it
// (the checkpoint holds the --set overrides, so none are repeated).
void say_how_to_resume(const RunOptions& o, const fs::path& out) {
  if (!fsi::coupling::CheckpointStore(out / "checkpoints", 1).newest()) return;
  const auto quote = [](const std::string& a) {
    return a.find_first_of(" '\"$\\") == std::string::npos ? a : "'" + a + "'";
  };
  std::string commands;
  if (!o.solid_command.empty()) commands += " --solid-command " + quote(o.solid_command);
  if (!o.fluid_command.empty()) commands += " --fluid-command " + quote(o.fluid_command);
  fsi::logger("fsi")->info("continue it with: {} run {} --out {} --resume{}",
                           quote(fs::read_symlink("/proc/self/exe").string()), quote(o.scene_path), quote(o.out_dir),
                           commands);
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
    after_coupler(p, e);
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

// The external solver commands (--solid-command, --fluid-command) a run was started with,
// kept in OUT/commands.json so that --resume starts the same processes.
const char* const kCommandsFile = "commands.json";

void remember_commands(const RunOptions& o) {
  write_json_atomic(fs::path(o.out_dir) / kCommandsFile,
                    {{"solid_command", o.solid_command}, {"fluid_command", o.fluid_command}});
}

// --resume: a command not given is taken from the run folder; one given that differs from the
// folder's is used, and the difference said.
void recall_commands(RunOptions& o, const RunOptions& given) {
  const auto stored = read_json(fs::path(o.out_dir) / kCommandsFile);
  if (!stored.is_object()) return;  // a folder of an older build: the commands as given
  auto log = fsi::logger("fsi");
  for (auto [option, key, value, was] :
       {std::tuple{"--solid-command", "solid_command", &o.solid_command, given.solid_command},
        std::tuple{"--fluid-command", "fluid_command", &o.fluid_command, given.fluid_command}}) {
    const std::string before = stored.value(key, std::string());
    if (was.empty() && !before.empty()) {
      *value = before;
      log->info("{} \"{}\" (as the run was started)", option, before);
    } else if (!was.empty() && was != before) {
      log->warn("{} \"{}\" differs from the one the run was started with ({}); using the one given", option, was,
                before.empty() ? std::string("the built-in server") : "\"" + before + "\"");
    }
  }
}

// --resume, checked before anything in --out is touched (a refused resume changes nothing):
// a coupled scene, a run folder with a complete checkpoint, and the scene that checkpoint was
// written with, up to time.end (which may grow: the run is extended). The overrides the run was
// started with are taken from the checkpoint, so `--resume` alone suffices; --set values given
// now come after them. Returns the overrides to run with, or nothing when the run is complete
// (nothing to do, nothing touched).
std::optional<std::vector<std::string>> prepare_resume(const RunOptions& o) {
  const fs::path out(o.out_dir);
  const auto refuse = [&](const std::string& why) {
    throw fsi::ConfigError(fmt::format("--resume '{}': {}; nothing in the folder was changed", o.out_dir, why));
  };
  std::vector<std::string> skipped;
  const auto ckpt = fsi::coupling::CheckpointStore(out / "checkpoints", 1).newest(&skipped);
  // A run killed as a whole before its first summary.json: its complete checkpoints prove it.
  if (!fs::exists(out / "summary.json") && !ckpt) refuse("not a run folder (no summary.json, no checkpoint)");
  if (!ckpt)
    refuse(fs::is_directory(out / "checkpoints")
               ? "no complete checkpoint in " + (out / "checkpoints").string() +
                     (skipped.empty() ? std::string() : " (" + skipped.front() + ")")
               : "the run wrote no checkpoints (time.checkpoint_every is 0, or the run stopped before its first "
                 "checkpoint), so it cannot be continued; run it again into another --out, or with --force");
  std::vector<std::string> overrides;
  for (const auto& ov : ckpt->manifest.value("overrides", nlohmann::json::array()))
    overrides.push_back(ov.get<std::string>());
  overrides.insert(overrides.end(), o.overrides.begin(), o.overrides.end());
  const auto scene = fsi::Scene::load(o.scene_path, overrides);
  if (!scene.has("coupling")) refuse("only coupled runs write checkpoints");
  std::vector<std::string> differ;
  bool extended = false;
  const double end = fsi::read_time(scene).end;
  for (const auto& d : fsi::coupling::parameter_differences(
           ckpt->manifest.value("parameters", nlohmann::json::object()), fsi::scene_to_json(scene))) {
    if (d.rfind("time.end:", 0) == 0)
      extended = true;
    else
      differ.push_back(d);
  }
  if (!differ.empty()) {
    // Another scene file altogether: say so first (the key list of two different scenes is long).
    const std::string was = ckpt->manifest.value("scene_file", std::string());
    std::error_code ec;
    if (!was.empty() && !fs::equivalent(fs::path(was), fs::path(o.scene_path), ec) &&
        ckpt->manifest.value("scene", std::string()) != scene.name())
      refuse(
          fmt::format("this folder was run with {} (scene '{}'), not {}: give that scene to --resume ({} keys "
                      "differ)",
                      was, ckpt->manifest.value("scene", std::string()), o.scene_path, differ.size()));
    std::string list;
    for (const auto& d : differ) list += "\n  " + d;
    refuse(fmt::format("the scene differs from the one checkpoint {} was written with (only time.end may change):{}",
                       ckpt->dir.string(), list));
  }
  if (end < ckpt->time - 1e-12 * std::max(1.0, end))
    refuse(fmt::format("time.end = {} is before the newest checkpoint (t = {})", end, ckpt->time));
  const auto summary = read_json(out / "summary.json");
  if (summary.is_object() && summary.value("status", std::string()) == "completed" && !extended) {
    fsi::logger("fsi")->info(
        "--resume '{}': the run is complete (t = {}), nothing to do; to extend it: --resume --set "
        "time.end=T",
        o.out_dir, end);
    return std::nullopt;
  }
  if (extended)
    fsi::logger("fsi")->info("extending the run to time.end = {} from the checkpoint of step {} (t = {})", end,
                             ckpt->step, ckpt->time);
  return overrides;
}

std::string python_interpreter();

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

// The Python interpreter of the project's Python tools: $FSI_PYTHON, else the one CMake found
// with numpy, yaml, zmq and protobuf (cmake/FsiPython.cmake).
std::string python_interpreter() {
  if (const char* env = std::getenv("FSI_PYTHON"); env && *env) return env;
#ifdef FSI_PYTHON
  return FSI_PYTHON;
#else
  return "/usr/bin/python3";
#endif
}

// `fsi study` / `fsi list`: hands over to the study tool (tools/fsi_study.py SUBCOMMAND) with every
// option passed on unchanged; a sweep also gets this executable as --fsi so every run uses the
// same build. Replaces this process; returns only on failure.
int study_tool(const std::string& subcommand, const std::vector<std::string>& tool_args) {
  // An installed fsi (PREFIX/bin) uses its own copy (PREFIX/share/fsi/tools, `cmake --install`),
  // a build tree the sources it was built from.
  fs::path tool = (self_dir() / ".." / "share" / "fsi" / "tools" / "fsi_study.py").lexically_normal();
#ifdef FSI_SOURCE_DIR
  if (!fs::exists(tool)) tool = fs::path(FSI_SOURCE_DIR) / "tools" / "fsi_study.py";
#endif
  if (!fs::exists(tool)) tool = self_dir() / ".." / ".." / "tools" / "fsi_study.py";
  if (!fs::exists(tool)) {
    fsi::logger("fsi")->error("study tool not found: {}", tool.string());
    return 1;
  }
  fsi::logger("fsi")->debug("study tool: {}", tool.string());
  const std::string self = fs::read_symlink("/proc/self/exe").string();
  std::vector<std::string> args{python_interpreter(), tool.string(), subcommand};
  args.insert(args.end(), tool_args.begin(), tool_args.end());
  if (subcommand == "run" || subcommand == "check") args.insert(args.end(), {"--fsi", self});
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  execvp(argv[0], argv.data());
  fsi::logger("fsi")->error("cannot start {} (set FSI_PYTHON to a python3 with numpy, yaml, zmq and protobuf): {}",
                            argv[0], std::strerror(errno));
  return 1;
}

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
  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);
  try {
    return run(o);
  } catch (const std::exception& e) {
    fsi::logger("fsi")->error("{}", e.what());
    return fsi::is_write_failure(e.what()) ? kExitWriteFailed : 1;
  }
}
