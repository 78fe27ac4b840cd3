#pragma once
// Continuing a run: --resume (checked before anything in --out is touched; time.end may grow: the run is
// extended), --from (a fork from another run's checkpoint), --initial-state, and the external commands a
// run was started with (OUT/commands.json).
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "fsi/coupling/checkpoint.hpp"
#include "run.hpp"

namespace fsi::launcher {

// --from PATH: the checkpoint folder (PATH itself when it holds a manifest.json, else the
// newest complete one under PATH/checkpoints), checked as the coupler checks it.
fsi::coupling::CheckpointStore::Loaded fork_checkpoint(const std::string& from, const std::string& option = "--from");

// Copies the checkpoint into OUT/checkpoints/ and writes OUT/forked_from.json: the coupler
// then continues from it with the scene as given now (changed keys allowed and listed).
void prepare_fork(const std::string& from, const std::filesystem::path& out);

// An interrupted or failed coupled run with a checkpoint: the exact command that continues it
// (the checkpoint holds the --set overrides, so none are repeated).
void say_how_to_resume(const RunOptions& o, const std::filesystem::path& out);

// The external solver commands (--solid-command, --fluid-command) a run was started with,
// kept in OUT/commands.json so that --resume starts the same processes.
void remember_commands(const RunOptions& o);

// --resume: a command not given is taken from the run folder; one given that differs from the
// folder's is used, and the difference said.
void recall_commands(RunOptions& o, const RunOptions& given);

// --resume, checked before anything in --out is touched (a refused resume changes nothing):
// a coupled scene, a run folder with a complete checkpoint, and the scene that checkpoint was
// written with, up to time.end (which may grow: the run is extended). The overrides the run was
// started with are taken from the checkpoint, so `--resume` alone suffices; --set values given
// now come after them. Returns the overrides to run with, or nothing when the run is complete
// (nothing to do, nothing touched).
std::optional<std::vector<std::string>> prepare_resume(const RunOptions& o);

}  // namespace fsi::launcher
