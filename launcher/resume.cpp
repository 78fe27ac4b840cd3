#include "resume.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <fstream>
#include <nlohmann/json.hpp>
#include <tuple>

#include "fsi/common/log.hpp"
#include "fsi/common/run_report.hpp"
#include "fsi/common/scene_reader.hpp"
#include "fsi/common/standalone.hpp"
#include "fsi/coupling/settings.hpp"
#include "run_folder.hpp"

namespace fs = std::filesystem;

namespace fsi::launcher {
namespace {

const char* const kCommandsFile = "commands.json";

// A table a resumed run continues (the coupler cuts it back to the checkpoint's step): "" when
// it has its header and at least `needed` complete rows of the header's width, else what is wrong.
std::string table_problem(const fs::path& file, std::size_t needed) {
  std::ifstream in(file, std::ios::binary);
  if (!in) return fmt::format("{} is missing", file.string());
  std::string header;
  if (!std::getline(in, header) || header.empty()) return fmt::format("{} has no header", file.string());
  const auto fields = [](const std::string& line) { return std::count(line.begin(), line.end(), ',') + 1; };
  std::size_t rows = 0;
  for (std::string line; rows < needed && std::getline(in, line);) {
    if (in.eof()) break;  // a row cut short (no newline): not complete
    if (fields(line) != fields(header))
      return fmt::format("{} line {} has {} fields, its header {}", file.string(), rows + 2, fields(line),
                         fields(header));
    ++rows;
  }
  if (rows < needed)
    return fmt::format("{} has {} complete rows, the checkpoint needs {}", file.string(), rows, needed);
  return "";
}

// Why a run folder without a complete checkpoint cannot be continued, from what the run wrote: its
// time.checkpoint_every (summary.json's parameters) and how far it got. The one cause that holds.
std::string why_no_checkpoint(const fs::path& out, const std::vector<std::string>& skipped) {
  if (fs::is_directory(out / "checkpoints") && !skipped.empty())
    return "no complete checkpoint in " + (out / "checkpoints").string() + " (" + skipped.front() + ")";
  // The run's effective scene (summary.json's parameters, JSON being YAML) with the declared defaults.
  std::optional<int> every;
  try {
    const auto summary = read_json(out / "summary.json");
    if (summary.is_object() && summary.contains("parameters"))
      every = fsi::read_time(fsi::Scene::parse(summary["parameters"].dump(), (out / "summary.json").string()))
                  .checkpoint_every;
  } catch (const std::exception&) {  // not readable: the cause is not known
  }
  const std::string then = "so it cannot be continued; run it again into another --out, or with --force";
  if (every && *every == 0)
    return "the run wrote no checkpoints: it was started with time.checkpoint_every: 0, " + then;
  if (every)
    return fmt::format(
        "the run wrote no checkpoints: it stopped after {} steps, before its first checkpoint "
        "(time.checkpoint_every: {}), {}",
        fsi::csv_rows(out / "probes.csv"), *every, then);
  return "the run wrote no checkpoints (its summary.json does not say its time.checkpoint_every), " + then;
}

// The tables the resumed run continues from checkpoint `ckpt` (a forked run's hold only the steps
// after its fork; a resume at the fork itself starts them afresh): "" when each is whole.
std::string tables_problem(const fs::path& out, const fsi::coupling::CheckpointStore::Loaded& ckpt) {
  const auto fork = read_json(out / "forked_from.json");
  const int fork_step = fork.is_object() ? fork.value("step", 0) : 0;
  const long fork_iterations = fork.is_object() ? fork.value("iterations", 0L) : 0L;
  if (fork.is_object() && ckpt.step == fork_step) return "";
  const auto steps = static_cast<std::size_t>(ckpt.step - fork_step);
  const auto iterations = static_cast<std::size_t>(ckpt.manifest.value("iterations", 0L) - fork_iterations);
  std::string problem = table_problem(out / "probes.csv", steps);
  if (problem.empty()) problem = table_problem(out / "iterations.csv", iterations);
  if (problem.empty() && fs::exists(out / "timing.csv")) problem = table_problem(out / "timing.csv", steps);
  return problem.empty() ? "" : fmt::format("{} (checkpoint of step {})", problem, ckpt.step);
}

}  // namespace

fsi::coupling::CheckpointStore::Loaded fork_checkpoint(const std::string& from, const std::string& option) {
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

void remember_commands(const RunOptions& o) {
  write_json_atomic(fs::path(o.out_dir) / kCommandsFile,
                    {{"solid_command", o.solid_command}, {"fluid_command", o.fluid_command}});
}

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

std::optional<std::vector<std::string>> prepare_resume(const RunOptions& o) {
  const fs::path out(o.out_dir);
  const auto refuse = [&](const std::string& why) {
    throw fsi::ConfigError(fmt::format("--resume '{}': {}; nothing in the folder was changed", o.out_dir, why));
  };
  std::vector<std::string> skipped;
  const auto ckpt = fsi::coupling::CheckpointStore(out / "checkpoints", 1).newest(&skipped);
  // A run killed as a whole before its first summary.json: its complete checkpoints prove it.
  if (!fs::exists(out / "summary.json") && !ckpt) refuse("not a run folder (no summary.json, no checkpoint)");
  if (!ckpt) refuse(why_no_checkpoint(out, skipped));
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
  // The tables before anything is touched: a damaged one is refused here, not by the coupler after
  // summary.json and the logs have been written.
  if (const std::string problem = tables_problem(out, *ckpt); !problem.empty())
    refuse(problem + ": the run cannot be continued from it");
  if (extended)
    fsi::logger("fsi")->info("extending the run to time.end = {} from the checkpoint of step {} (t = {})", end,
                             ckpt->step, ckpt->time);
  return overrides;
}

}  // namespace fsi::launcher
