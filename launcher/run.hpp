#pragma once
// fsi run: a scene checked, then one solver alone or the coupled processes with their recovery; the
// options of the command and the launcher's last word on a run.
#include <string>
#include <vector>

namespace fsi::launcher {

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

// The coupler's (and a standalone run's) exit code when an output file could not be written
// (a full disk): EX_IOERR of sysexits.h, passed on by fsi run.
constexpr int kExitWriteFailed = 74;

// The launcher's last word on a run: its exit code, and the status and reason it writes into
// summary.json (empty: the run's own summary stands).
struct Ending {
  int code = 1;
  std::string status, reason;
};

// `fsi run`: the exit code (0 completed, 2 diverged, 1 failed, 130 interrupted, 74 an output file could not be
// written).
int run(const RunOptions& given);

}  // namespace fsi::launcher
