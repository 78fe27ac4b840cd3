#include "processes.hpp"

#include <fmt/format.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstring>
#include <fstream>
#include <stdexcept>
#include <thread>

#include "fsi/common/log.hpp"
#include "fsi/common/scene_reader.hpp"
#include "fsi/common/scene_schema.hpp"
#include "fsi/models/fluid_factory.hpp"

namespace fs = std::filesystem;

namespace fsi::launcher {
namespace {

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

}  // namespace

std::vector<char*> c_argv(std::vector<std::string>& args) {
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  return argv;
}

volatile std::sig_atomic_t g_signal = 0;
extern "C" void on_signal(int sig) { g_signal = sig; }

Child spawn(const std::string& name, const std::vector<std::string>& argv, const fs::path& log,
            const std::string& shell_command) {
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
      std::vector<std::string> copy = argv;
      auto args = c_argv(copy);
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

void stop_all(std::vector<Child*> children, std::chrono::milliseconds grace, std::chrono::milliseconds term_wait) {
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

}  // namespace fsi::launcher
