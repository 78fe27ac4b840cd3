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
// Exit code: the coupler's (0 completed, 2 diverged, 1 failed).
#include <CLI/CLI.hpp>
#include <fmt/format.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstring>
#include <map>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <thread>
#include <vector>

#include "fsi/common/config.hpp"
#include "fsi/common/log.hpp"

namespace fs = std::filesystem;

namespace {

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
    setpgid(0, 0);                     // own process group: Ctrl-C goes through the launcher
    if (!log.empty()) {
      FILE* f = std::fopen(log.c_str(), "w");
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

// Stops a child: waits `grace`, then SIGTERM, then SIGKILL. Always reaps.
void stop(Child& c, std::chrono::milliseconds grace) {
  const auto until = [&](std::chrono::milliseconds d) {
    const auto end = std::chrono::steady_clock::now() + d;
    while (c.alive() && std::chrono::steady_clock::now() < end) {
      reap(c, false);
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
  };
  until(grace);
  if (c.alive()) {
    kill(-c.pid, SIGTERM);
    kill(c.pid, SIGTERM);
    until(std::chrono::seconds(3));
  }
  if (c.alive()) {
    kill(-c.pid, SIGKILL);
    kill(c.pid, SIGKILL);
    reap(c, true);
  }
}

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

int run(const std::string& scene_path, const std::string& out_dir, const std::vector<std::string>& overrides,
        const std::string& solid_command, const std::string& fluid_command, double timeout) {
  auto log = fsi::logger("fsi");
  const auto scene = fsi::Scene::load(scene_path, overrides);  // fails early on a bad file
  const bool has_solid = scene.has("solid"), has_fluid = scene.has("fluid"), coupled = scene.has("coupling");
  const fs::path out(out_dir), bin = self_dir();
  fs::create_directories(out);
  std::vector<std::string> sets;
  for (const auto& o : overrides) sets.insert(sets.end(), {"--set", o});

  std::vector<Child> children;
  int code = 1;
  try {
    if (!coupled) {
      // One solver alone.
      if (has_solid == has_fluid)
        throw fsi::ConfigError(scene_path + ": a scene without 'coupling' must have exactly one of 'solid' or 'fluid'");
      const std::string server = has_solid ? "solid_server" : "fluid_server";
      std::vector<std::string> argv{(bin / server).string(), "--standalone", scene_path, "--out", out_dir};
      argv.insert(argv.end(), sets.begin(), sets.end());
      log->info("scene '{}': {} alone", scene_path, server);
      children.push_back(spawn(server, argv, ""));
    } else {
      if (!has_solid || !has_fluid) throw fsi::ConfigError(scene_path + ": a coupled scene needs 'solid' and 'fluid'");
      const fs::path ports = out / ".ports";
      fs::create_directories(ports);
      std::map<std::string, std::string> endpoints;
      for (const auto& [side, command] : {std::pair{std::string("solid"), solid_command}, {"fluid", fluid_command}}) {
        const std::string server = side + "_server";
        const fs::path port_file = ports / (side + ".port");
        fs::remove(port_file);
        const fs::path server_log = out / (server + ".log");
        if (command.empty()) {
          children.push_back(spawn(server, {(bin / server).string(), "--bind", "tcp://127.0.0.1:*", "--port-file",
                                            port_file.string()},
                                   server_log));
        } else {
          const std::string shell = fmt::format("exec {} --bind 'tcp://127.0.0.1:*' --port-file '{}'", command,
                                                port_file.string());
          children.push_back(spawn(server + " (external)", {}, server_log, shell));
        }
        endpoints[side] = wait_for_endpoint(children.back(), port_file, std::chrono::seconds(30));
        log->info("{} listening on {} (log: {})", children.back().name, endpoints[side], server_log.string());
      }
      std::vector<std::string> argv{(bin / "coupler").string(), scene_path, "--solid", endpoints["solid"], "--fluid",
                                    endpoints["fluid"], "--out", out_dir, "--timeout", fmt::format("{}", timeout)};
      argv.insert(argv.end(), sets.begin(), sets.end());
      children.push_back(spawn("coupler", argv, ""));
    }
    // Wait for the main process (the last one) to finish; forward Ctrl-C.
    Child& main = children.back();
    bool forwarded = false;
    while (main.alive()) {
      reap(main, false);
      if (g_signal && !forwarded) {
        log->warn("signal received: stopping {}", main.name);
        kill(main.pid, SIGINT);
        forwarded = true;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    code = main.status;
    for (auto& c : children) {
      reap(c, false);
      if (&c != &main && c.status > 0) log->error("{} exited with code {}; its log ({}):\n{}", c.name, c.status,
                                                  c.log.string(), tail(c.log, 10));
    }
  } catch (const std::exception& e) {
    log->error("{}", e.what());
    code = 1;
  }
  for (auto& c : children) stop(c, std::chrono::seconds(5));
  if (g_signal && code == 0) code = 130;
  return code;
}

// `fsi study`: hands the sweep to tools/fsi_study.py (Debian's python3), passing this executable
// as --fsi so every run uses the same build. Replaces this process; returns only on failure.
int study(const std::string& study_file, const std::string& out_dir, int jobs) {
#ifdef FSI_SOURCE_DIR
  fs::path tool = fs::path(FSI_SOURCE_DIR) / "tools" / "fsi_study.py";
#else
  fs::path tool;
#endif
  if (tool.empty() || !fs::exists(tool)) tool = self_dir() / ".." / ".." / "tools" / "fsi_study.py";
  if (!fs::exists(tool)) {
    fsi::logger("fsi")->error("study tool not found: {}", tool.string());
    return 1;
  }
  const std::string self = fs::read_symlink("/proc/self/exe").string();
  std::vector<std::string> args{"/usr/bin/python3", tool.string(), "run", study_file, "--out", out_dir, "--fsi", self};
  if (jobs > 0) args.insert(args.end(), {"--jobs", std::to_string(jobs)});
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  execv(argv[0], argv.data());
  fsi::logger("fsi")->error("cannot start {}: {}", argv[0], std::strerror(errno));
  return 1;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"fsi: partitioned fluid-structure interaction co-simulation"};
  app.require_subcommand(1);
  auto* run_cmd = app.add_subcommand("run", "run one scene, starting only the processes it needs");
  std::string scene, out = "runs/latest", solid_command, fluid_command;
  std::vector<std::string> overrides;
  double timeout = 600;
  run_cmd->add_option("scene", scene, "scene file (configs/*.yaml)")->required()->check(CLI::ExistingFile);
  run_cmd->add_option("--out", out, "output folder (summary.json, probes.csv, iterations.csv, logs, vtk/)");
  run_cmd->add_option("--set", overrides, "override any scene key: dotted.key=value (repeatable)");
  run_cmd->add_option("--solid-command", solid_command,
                      "start this external solid instead of solid_server (gets --bind and --port-file)");
  run_cmd->add_option("--fluid-command", fluid_command, "start this external fluid instead of fluid_server");
  run_cmd->add_option("--timeout", timeout, "seconds the coupler waits for any single reply");
  auto* study_cmd = app.add_subcommand("study", "run a parameter study (tools/fsi_study.py run; docs/studies.md)");
  std::string study_file, study_out = "runs/study";
  int jobs = 0;
  study_cmd->add_option("study", study_file, "study file (studies/*.yaml)")->required()->check(CLI::ExistingFile);
  study_cmd->add_option("--out", study_out, "study folder (results.csv, results.json, runs/)");
  study_cmd->add_option("--jobs", jobs, "parallel runs (default: number of cores)");
  CLI11_PARSE(app, argc, argv);
  if (study_cmd->parsed()) return study(study_file, study_out, jobs);
  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);
  try {
    return run(scene, out, overrides, solid_command, fluid_command, timeout);
  } catch (const std::exception& e) {
    fsi::logger("fsi")->error("{}", e.what());
    return 1;
  }
}
