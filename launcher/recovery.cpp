#include "recovery.hpp"

#include <fmt/format.h>
#include <unistd.h>

#include <csignal>
#include <nlohmann/json.hpp>

#include "fsi/common/log.hpp"
#include "fsi/common/run_report.hpp"
#include "run_folder.hpp"

namespace fs = std::filesystem;

namespace fsi::launcher {
namespace {

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

}  // namespace

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

void after_coupler(const fs::path& out, int checkpoint_every, CoupledProcesses& p, Ending& e) {
  auto log = fsi::logger("fsi");
  if (e.code > 128 && e.code != 130) {
    // The coupler itself died: say so at once, stop both servers together. What a resume can do
    // depends on what the run wrote: the one that holds is said.
    const nlohmann::json checkpoint = newest_checkpoint(out);
    const std::string then =
        checkpoint.is_object()  ? fmt::format("`fsi run ... --resume` continues from the checkpoint of step {}",
                                              checkpoint.value("step", 0))
        : checkpoint_every == 0 ? std::string("no checkpoint to continue from (time.checkpoint_every: 0)")
                                : fmt::format(
                                      "no checkpoint to continue from: it died after {} steps, before its first "
                                      "(time.checkpoint_every: {})",
                                      fsi::csv_rows(out / "probes.csv"), checkpoint_every);
    e.status = "failed";
    e.reason = fmt::format("the coupler was killed by {} ({}); {}", signal_name(e.code - 128), e.code - 128, then);
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

}  // namespace fsi::launcher
