#pragma once
// A coupled run's processes and their recovery: the two servers started on free loopback ports, the
// coupler run until it ends, and a server that dies or stops answering started again (--recover).
#include <filesystem>
#include <string>
#include <vector>

#include "processes.hpp"
#include "run.hpp"

namespace fsi::launcher {

// The processes of a coupled run: the two servers (solid, fluid) and the coupler.
struct CoupledProcesses {
  std::vector<Server> servers;
  std::vector<Child> children = std::vector<Child>(2);  // solid, fluid
  Child coupler;
};

// Starts both servers on free loopback ports.
void start_servers(const RunOptions& o, const std::filesystem::path& ports, CoupledProcesses& p,
                   const std::vector<std::string>& fluid_mpi);

// Runs the coupler until it ends; with `recover` > 0, a server that dies or stops answering
// is started again and the run resumes from the last checkpoint, up to `recover` times.
Ending run_with_recovery(const RunOptions& o, CoupledProcesses& p, int recover, const std::vector<std::string>& sets);

// After the coupler: a coupler killed by a signal stops both servers at once (the reason says
// whether and from which checkpoint of `out` the run can be continued); a server that failed on
// its own shows its log.
void after_coupler(const std::filesystem::path& out, int checkpoint_every, CoupledProcesses& p, Ending& e);

}  // namespace fsi::launcher
