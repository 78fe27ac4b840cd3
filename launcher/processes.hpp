#pragma once
// fsi run's processes: starting a server or the coupler (its own process group, its log), waiting for a
// server's endpoint, stopping them together, and the signals the launcher receives.
#include <sys/types.h>

#include <chrono>
#include <csignal>
#include <filesystem>
#include <string>
#include <vector>

#include "fsi/common/config.hpp"

namespace fsi::launcher {

// Launcher limits: a server must write its port file within --start-timeout (60 s) of starting and answer
// the coupler's Hello within half of it (generous: a loaded machine, a Python solver importing its modules); at
// the end each process gets 3 s to exit after Stop (1 s when the run failed: a server that never answered got no
// Stop it could obey), then SIGTERM, then SIGKILL 0.5 s later.

// The signal (SIGINT, SIGTERM) the launcher received, 0 if none; set by on_signal.
extern volatile std::sig_atomic_t g_signal;
extern "C" void on_signal(int sig);

struct Child {
  std::string name;
  pid_t pid = -1;
  std::filesystem::path log;
  int status = -1;  // exit code once reaped
  bool alive() const { return pid > 0 && status < 0; }
};

// argv for execv / execvp: pointers into `args` (which must outlive them), null-terminated.
std::vector<char*> c_argv(std::vector<std::string>& args);

// Starts `argv` (or `/bin/sh -c shell_command`) with stdout/stderr to `log` (empty = inherit).
Child spawn(const std::string& name, const std::vector<std::string>& argv, const std::filesystem::path& log,
            const std::string& shell_command = "");

// Records the child's exit code (128 + the signal when killed) once it has ended; `block`: waits for that.
void reap(Child& c, bool block);

// Stops children together: waits up to `grace` for them to exit by themselves, then
// SIGTERM to all, up to `term_wait`, then SIGKILL. Always reaps.
void stop_all(std::vector<Child*> children, std::chrono::milliseconds grace,
              std::chrono::milliseconds term_wait = std::chrono::milliseconds(500));
void stop(Child& c, std::chrono::milliseconds grace);

// The last `lines` lines of `file`, each indented by four spaces.
std::string tail(const std::filesystem::path& file, int lines);

// Waits for a server to write its bound endpoint.
std::string wait_for_endpoint(Child& c, const std::filesystem::path& port_file, std::chrono::seconds timeout);

// The folder of this executable (the servers and the coupler are beside it).
std::filesystem::path self_dir();

// "SIGTERM" etc. for the signals a process is stopped or killed with, else "a signal".
const char* signal_name(int sig);

struct Server {
  std::string side;     // "solid" / "fluid"
  std::string command;  // external command ("" = ours)
  std::string endpoint;
  std::filesystem::path port_file, log;
  std::string curve_keys;             // CURVE key folder ("" = none)
  std::vector<std::string> mpi = {};  // our server under the MPI launcher (fluid.ranks > 1)
};

// fluid.ranks > 1: the command line that starts fluid_server on that many MPI ranks
// (fluid.mpi: command, hostfile, args); empty for one rank (no MPI launcher at all).
std::vector<std::string> fluid_mpi_launcher(const fsi::Scene& scene);

// Starts a server listening on `bind` (ours from `bin`, or its external command) and waits up to `timeout`
// for its endpoint (s.endpoint); a server that does not report one is stopped.
Child start_server(Server& s, const std::filesystem::path& bin, const std::string& bind, std::chrono::seconds timeout);

// Waits for `child`, forwarding a SIGINT/SIGTERM the launcher receives to it once.
void wait_forwarding_signals(Child& child, std::chrono::milliseconds poll, bool warn);

}  // namespace fsi::launcher
