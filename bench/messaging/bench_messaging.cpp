// bench_messaging: what one coupling iteration costs in messaging, for 100, 1,000 and
// 10,000 interface nodes (a benchmark, not a test).
//
// Two real server processes over tcp loopback, exactly the stack the coupler uses:
//   parent  RemoteSolid / RemoteFluid -> ProtocolClient -> transport::Client (DEALER)
//   child   transport::Server (ROUTER) -> SolidService / FluidService -> echo model
// The echo models do no work: a solid that answers SolveStep (2n interface forces) with
// 2n displacements + 2n velocities, a fluid that answers SolveStep (2n displacements + 2n
// velocities) with 2n traction forces + 2n velocity integrals. One coupling iteration =
// one solid round trip + one fluid round trip, as in the coupler's inner loop.
//
// Sample runs:
//   bench_messaging                                    # 100 / 1,000 / 10,000 nodes
//   bench_messaging --runs 3 --out messaging.csv       # medians of 3 runs, CSV
//   bench_messaging --nodes 1000 --iterations 5000 --out m.json
#include <fmt/format.h>
#include <poll.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstring>
#include <fstream>
#include <functional>
#include <nlohmann/json.hpp>
#include <thread>

#include "fsi/common/config.hpp"
#include "fsi/common/process.hpp"
#include "fsi/common/version.hpp"
#include "fsi/protocol/client.hpp"
#include "fsi/protocol/remote.hpp"
#include "fsi/protocol/service.hpp"
#include "fsi/transport/transport.hpp"

namespace {

using Clock = std::chrono::steady_clock;
using std::chrono::milliseconds;

// ---------------------------------------------------------------------------- echo models
// Interface of n nodes on a line; n is the scene key `nodes`.
fsi::InterfaceMeshData line_interface(int n) {
  fsi::InterfaceMeshData data;
  data.coordinates.resize(n, 2);
  for (int i = 0; i < n; ++i) {
    data.node_ids.push_back(i);
    data.coordinates(i, 0) = i / static_cast<double>(n);
    data.coordinates(i, 1) = 0.0;
    if (i > 0) data.segments.push_back({i - 1, i});
  }
  return data;
}

class EchoSolid : public fsi::SolidModel {
 public:
  std::string name() const override { return "echo solid"; }
  void configure(const fsi::ConfigSection& s, const fsi::SolidSetup&) override {
    n_ = s.get<int>("nodes");
    if (n_ < 1) s.fail("nodes", "must be >= 1");
  }
  fsi::InterfaceMeshData interface() const override { return line_interface(n_); }
  fsi::SolidStepResult solve_step(const fsi::StepInfo& info, const Eigen::VectorXd& f) override {
    return {1e-3 * f, (1e-3 / info.dt) * f, 1, {}, {}};
  }
  std::map<std::string, double> accept_step(const fsi::StepInfo&) override { return {}; }

 private:
  int n_ = 0;
};

class EchoFluid : public fsi::FluidModel {
 public:
  std::string name() const override { return "echo fluid"; }
  void configure(const fsi::ConfigSection& s, const fsi::FluidSetup&) override {
    n_ = s.get<int>("nodes");
    if (n_ < 1) s.fail("nodes", "must be >= 1");
  }
  fsi::InterfaceMeshData interface() const override { return line_interface(n_); }
  fsi::FluidLoads initial_loads(const Eigen::VectorXd& d, const Eigen::VectorXd& v) override {
    return {-d, v, 1, {}, {}, {}};
  }
  fsi::FluidLoads solve_step(const fsi::StepInfo&, const Eigen::VectorXd& d, const Eigen::VectorXd& v) override {
    return {-1e3 * d, v, 1, {}, {}, {}};  // traction = -force on the solid: the loop stays bounded
  }
  std::map<std::string, double> accept_step(const fsi::StepInfo&) override { return {}; }

 private:
  int n_ = 0;
};

std::unique_ptr<fsi::protocol::Service> make_service(const std::string& kind) {
  if (kind == "solid")
    return std::make_unique<fsi::protocol::SolidService>(
        [](const std::string& m) { return m == "echo" ? std::make_unique<EchoSolid>() : nullptr; }, "bench echo solid");
  return std::make_unique<fsi::protocol::FluidService>(
      [](const std::string& m) { return m == "echo" ? std::make_unique<EchoFluid>() : nullptr; }, "bench echo fluid");
}

std::string scene_text(int n) {
  return fmt::format("solid:\n  model: echo\n  nodes: {0}\nfluid:\n  model: echo\n  nodes: {0}\n", n);
}

// ---------------------------------------------------------------------------- child processes
// A forked server process. The destructor always ends and reaps it (bounded waits).
class ChildServer {
 public:
  ChildServer(const std::string& kind, milliseconds start_timeout) : kind_(kind) {
    int fds[2];
    if (pipe(fds) != 0) throw std::runtime_error(fmt::format("pipe: {}", std::strerror(errno)));
    const pid_t parent = getpid();
    pid_ = fork();
    if (pid_ < 0) {
      close(fds[0]);
      close(fds[1]);
      throw std::runtime_error(fmt::format("fork: {}", std::strerror(errno)));
    }
    if (pid_ == 0) {
      close(fds[0]);
      prctl(PR_SET_PDEATHSIG, SIGKILL);  // never outlive the benchmark
      if (getppid() != parent) _exit(1);
      _exit(serve(kind, fds[1]));
    }
    close(fds[1]);
    try {
      endpoint_ = read_endpoint(fds[0], start_timeout);
    } catch (...) {
      close(fds[0]);
      finish(milliseconds(0));
      throw;
    }
    close(fds[0]);
  }
  ~ChildServer() { finish(milliseconds(3000)); }
  ChildServer(const ChildServer&) = delete;
  ChildServer& operator=(const ChildServer&) = delete;
  const std::string& endpoint() const { return endpoint_; }

  // Waits up to `grace` for a clean exit (after Stop), then SIGKILL; always reaps.
  int finish(milliseconds grace) {
    if (pid_ <= 0) return status_;
    const auto end = Clock::now() + grace;
    while (!reaped(WNOHANG) && Clock::now() < end) std::this_thread::sleep_for(milliseconds(5));
    if (pid_ > 0) {
      kill(pid_, SIGKILL);
      reaped(0);  // bounded: the child has been SIGKILLed
    }
    return status_;
  }

 private:
  // Child side: bind a free loopback port, report it through the pipe, serve.
  static int serve(const std::string& kind, int fd) {
    auto report = [fd](const std::string& line) {
      const std::string s = line + "\n";
      [[maybe_unused]] auto w = write(fd, s.data(), s.size());
      close(fd);
    };
    try {
      const auto service = make_service(kind);
      fsi::transport::Server server("tcp://127.0.0.1:*");
      report(server.endpoint());
      // Idle timeout: a parent that vanished without Stop does not leave us behind.
      const bool clean = server.serve([&](const std::string& bytes, const std::string& peer,
                                          bool& stop) { return service->handle_bytes(bytes, stop, peer); },
                                      std::chrono::seconds(60));
      return clean ? 0 : 3;
    } catch (const std::exception& e) {
      report(std::string("ERROR ") + e.what());
      return 1;
    }
  }

  std::string read_endpoint(int fd, milliseconds timeout) {
    const auto end = Clock::now() + timeout;
    std::string line;
    while (line.find('\n') == std::string::npos) {
      const auto left = std::chrono::duration_cast<milliseconds>(end - Clock::now()).count();
      if (left <= 0)
        throw std::runtime_error(
            fmt::format("{} server did not report its endpoint within {} ms", kind_, timeout.count()));
      pollfd p{fd, POLLIN, 0};
      const int r = poll(&p, 1, static_cast<int>(left));
      if (r < 0 && errno == EINTR) continue;
      if (r <= 0) continue;
      char buf[256];
      const ssize_t got = read(fd, buf, sizeof buf);
      if (got < 0 && errno == EINTR) continue;
      if (got <= 0) throw std::runtime_error(fmt::format("{} server exited before reporting its endpoint", kind_));
      line.append(buf, static_cast<std::size_t>(got));
    }
    line.resize(line.find('\n'));
    if (line.rfind("ERROR ", 0) == 0) throw std::runtime_error(kind_ + " server: " + line.substr(6));
    return line;
  }

  bool reaped(int flags) {
    int status = 0;
    pid_t r;
    do r = waitpid(pid_, &status, flags);
    while (r < 0 && errno == EINTR);
    if (r == pid_ || (r < 0 && errno == ECHILD)) {
      status_ = r == pid_ ? (WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status)) : -1;
      pid_ = -1;
      return true;
    }
    return false;
  }

  std::string kind_;
  pid_t pid_ = -1;
  int status_ = -1;
  std::string endpoint_;
};

// ---------------------------------------------------------------------------- statistics
double percentile(std::vector<double> v, double p) {  // nearest rank
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  const auto rank = static_cast<std::size_t>(std::ceil(p / 100.0 * static_cast<double>(v.size())));
  return v[std::clamp<std::size_t>(rank, 1, v.size()) - 1];
}
double median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  const std::size_t m = v.size() / 2;
  return v.size() % 2 ? v[m] : 0.5 * (v[m - 1] + v[m]);
}

struct Row {
  int nodes = 0;
  std::string run;  // "1", "2", ... or "median"
  int iterations = 0;
  std::size_t solid_request = 0, solid_reply = 0, fluid_request = 0, fluid_reply = 0;
  double codec_med = 0;  // the same messages through both services in-process (no sockets)
  double solid_med = 0, solid_p99 = 0, fluid_med = 0, fluid_p99 = 0, iter_med = 0, iter_p99 = 0;
};

// Payload bytes of the messages RemoteSolid / RemoteFluid exchange (protobuf, excluding
// ZeroMQ framing), built the same way.
void message_sizes(int n, Row& row) {
  const Eigen::VectorXd x = Eigen::VectorXd::Constant(2 * n, 0.123456789);
  auto request = [&](bool solid) {
    fsi::v1::Request r;
    r.set_protocol_version(fsi::protocol::kProtocolVersion);
    r.set_sequence(123456);
    auto* s = r.mutable_solve_step();
    s->set_time(1.0);
    s->set_dt(0.01);
    s->set_step(100);
    s->set_iteration(3);
    if (solid) {
      fsi::protocol::from_eigen(x, s->mutable_interface_force());
    } else {
      fsi::protocol::from_eigen(x, s->mutable_interface_displacement());
      fsi::protocol::from_eigen(x, s->mutable_interface_velocity());
    }
    return r.ByteSizeLong();
  };
  auto reply = [&](bool solid) {
    fsi::v1::Reply r;
    r.set_protocol_version(fsi::protocol::kProtocolVersion);
    r.set_sequence(123456);
    r.set_compute_seconds(1e-6);
    if (solid) {
      fsi::protocol::from_eigen(x, r.mutable_solid_step()->mutable_interface_displacement());
      fsi::protocol::from_eigen(x, r.mutable_solid_step()->mutable_interface_velocity());
      r.mutable_solid_step()->set_newton_iterations(1);
    } else {
      fsi::protocol::from_eigen(x, r.mutable_fluid_loads()->mutable_traction_force());
      fsi::protocol::from_eigen(x, r.mutable_fluid_loads()->mutable_velocity_integral());
      r.mutable_fluid_loads()->set_nonlinear_iterations(1);
    }
    return r.ByteSizeLong();
  };
  row.solid_request = request(true);
  row.solid_reply = reply(true);
  row.fluid_request = request(false);
  row.fluid_reply = reply(false);
}

// The protocol work of one coupling iteration without sockets: Eigen -> protobuf, serialise,
// the services' parse + dispatch + serialise, parse, protobuf -> Eigen. Median microseconds.
double codec_us(int n, int iterations) {
  auto solid = make_service("solid"), fluid = make_service("fluid");
  bool stop = false;
  for (auto* service : {solid.get(), fluid.get()}) {
    fsi::v1::Request r;
    r.set_protocol_version(fsi::protocol::kProtocolVersion);
    r.mutable_configure()->set_dt(0.01);
    r.mutable_configure()->set_scene_text(scene_text(n));
    r.mutable_configure()->set_section(service == solid.get() ? "solid" : "fluid");
    const auto reply = service->handle(r, stop);
    if (reply.has_error()) throw std::runtime_error("in-process configure: " + reply.error().message());
  }
  Eigen::VectorXd force = Eigen::VectorXd::LinSpaced(2 * n, 1.0, 2.0);
  std::vector<double> t;
  std::uint64_t seq = 0;
  for (int i = 0; i < iterations + iterations / 10; ++i) {
    const auto t0 = Clock::now();
    fsi::v1::Request rs;
    rs.set_protocol_version(fsi::protocol::kProtocolVersion);
    rs.set_sequence(++seq);
    rs.mutable_solve_step()->set_dt(0.01);
    fsi::protocol::from_eigen(force, rs.mutable_solve_step()->mutable_interface_force());
    fsi::v1::Reply s;
    if (!s.ParseFromString(solid->handle_bytes(rs.SerializeAsString(), stop)) || !s.has_solid_step())
      throw std::runtime_error("in-process solid step failed");
    fsi::v1::Request rf;
    rf.set_protocol_version(fsi::protocol::kProtocolVersion);
    rf.set_sequence(++seq);
    rf.mutable_solve_step()->set_dt(0.01);
    fsi::protocol::from_eigen(fsi::protocol::to_eigen(s.solid_step().interface_displacement()),
                              rf.mutable_solve_step()->mutable_interface_displacement());
    fsi::protocol::from_eigen(fsi::protocol::to_eigen(s.solid_step().interface_velocity()),
                              rf.mutable_solve_step()->mutable_interface_velocity());
    fsi::v1::Reply f;
    if (!f.ParseFromString(fluid->handle_bytes(rf.SerializeAsString(), stop)) || !f.has_fluid_loads())
      throw std::runtime_error("in-process fluid step failed");
    force = -fsi::protocol::to_eigen(f.fluid_loads().traction_force());
    const Eigen::VectorXd vi = fsi::protocol::to_eigen(f.fluid_loads().velocity_integral());
    const auto t1 = Clock::now();
    if (i >= iterations / 10) t.push_back(std::chrono::duration<double, std::micro>(t1 - t0).count() + 0 * vi[0]);
  }
  return median(t);
}

// One measurement: configure both servers for n nodes, warm up, time `iterations`.
Row measure(fsi::protocol::RemoteSolid& solid, fsi::protocol::RemoteFluid& fluid, int n, int warmup, int iterations) {
  const auto scene = fsi::Scene::parse(scene_text(n), "<bench_messaging>");
  const double dt = 0.01;
  solid.configure(scene.section("solid"), fsi::SolidSetup{dt, 1.0, 0.0, {}});
  fluid.configure(scene.section("fluid"), fsi::FluidSetup{dt, 1.0, 0.0, -1.0, {}});
  if (solid.interface().nodes() != static_cast<std::size_t>(n) ||
      fluid.interface().nodes() != static_cast<std::size_t>(n))
    throw std::runtime_error(fmt::format("servers report {} / {} interface nodes, expected {}",
                                         solid.interface().nodes(), fluid.interface().nodes(), n));

  Eigen::VectorXd force = Eigen::VectorXd::LinSpaced(2 * n, 1.0, 2.0);
  std::vector<double> t_solid, t_fluid, t_iter;
  t_solid.reserve(iterations);
  t_fluid.reserve(iterations);
  t_iter.reserve(iterations);
  int step = 1, k = 1;
  for (int i = 0; i < warmup + iterations; ++i) {
    const fsi::StepInfo info{step * dt, dt, step, k};
    const auto t0 = Clock::now();
    const fsi::SolidStepResult s = solid.solve_step(info, force);
    const auto t1 = Clock::now();
    const fsi::FluidLoads loads = fluid.solve_step(info, s.interface_displacement, s.interface_velocity);
    const auto t2 = Clock::now();
    force = -loads.traction_force;  // the next iteration's input, as in the coupler
    if (++k > 5) k = 1, ++step;
    if (i < warmup) continue;
    t_solid.push_back(std::chrono::duration<double, std::micro>(t1 - t0).count());
    t_fluid.push_back(std::chrono::duration<double, std::micro>(t2 - t1).count());
    t_iter.push_back(std::chrono::duration<double, std::micro>(t2 - t0).count());
  }
  Row row;
  row.nodes = n;
  row.iterations = iterations;
  message_sizes(n, row);
  row.codec_med = codec_us(n, iterations);
  row.solid_med = median(t_solid);
  row.solid_p99 = percentile(t_solid, 99);
  row.fluid_med = median(t_fluid);
  row.fluid_p99 = percentile(t_fluid, 99);
  row.iter_med = median(t_iter);
  row.iter_p99 = percentile(t_iter, 99);
  return row;
}

Row median_of(const std::vector<Row>& runs) {
  Row m = runs.front();
  m.run = "median";
  auto med = [&](double Row::*field) {
    std::vector<double> v;
    for (const auto& r : runs) v.push_back(r.*field);
    return median(v);
  };
  m.codec_med = med(&Row::codec_med);
  m.solid_med = med(&Row::solid_med);
  m.solid_p99 = med(&Row::solid_p99);
  m.fluid_med = med(&Row::fluid_med);
  m.fluid_p99 = med(&Row::fluid_p99);
  m.iter_med = med(&Row::iter_med);
  m.iter_p99 = med(&Row::iter_p99);
  return m;
}

std::string kb(std::size_t bytes) { return fmt::format("{:.1f} KB", bytes / 1000.0); }

void print_table(const std::vector<Row>& rows) {
  fmt::print(
      "\n| nodes | run | iterations | solid req / reply | fluid req / reply | solid round trip med / p99 us "
      "| fluid round trip med / p99 us | coupling iteration med / p99 us | of which protocol (no sockets) us |\n");
  fmt::print("|---|---|---|---|---|---|---|---|---|\n");
  for (const auto& r : rows)
    fmt::print("| {} | {} | {} | {} / {} | {} / {} | {:.0f} / {:.0f} | {:.0f} / {:.0f} | {:.0f} / {:.0f} | {:.0f} |\n",
               r.nodes, r.run, r.iterations, kb(r.solid_request), kb(r.solid_reply), kb(r.fluid_request),
               kb(r.fluid_reply), r.solid_med, r.solid_p99, r.fluid_med, r.fluid_p99, r.iter_med, r.iter_p99,
               r.codec_med);
}

void write_out(const std::string& path, const std::vector<Row>& rows) {
  std::ofstream out(path);
  if (!out) throw std::runtime_error("cannot write '" + path + "'");
  const bool json = path.size() >= 5 && path.substr(path.size() - 5) == ".json";
  if (json) {
    nlohmann::json j = nlohmann::json::array();
    for (const auto& r : rows)
      j.push_back({{"nodes", r.nodes},
                   {"run", r.run},
                   {"iterations", r.iterations},
                   {"bytes",
                    {{"solid_request", r.solid_request},
                     {"solid_reply", r.solid_reply},
                     {"fluid_request", r.fluid_request},
                     {"fluid_reply", r.fluid_reply}}},
                   {"solid_round_trip_us", {{"median", r.solid_med}, {"p99", r.solid_p99}}},
                   {"fluid_round_trip_us", {{"median", r.fluid_med}, {"p99", r.fluid_p99}}},
                   {"coupling_iteration_us", {{"median", r.iter_med}, {"p99", r.iter_p99}}},
                   {"protocol_no_sockets_us", {{"median", r.codec_med}}}});
    out << j.dump(2) << '\n';
  } else {
    out << "nodes,run,iterations,solid_request_bytes,solid_reply_bytes,fluid_request_bytes,fluid_reply_bytes,"
           "solid_rt_median_us,solid_rt_p99_us,fluid_rt_median_us,fluid_rt_p99_us,iteration_median_us,"
           "iteration_p99_us,protocol_no_sockets_median_us\n";
    for (const auto& r : rows)
      out << fmt::format("{},{},{},{},{},{},{},{:.2f},{:.2f},{:.2f},{:.2f},{:.2f},{:.2f},{:.2f}\n", r.nodes, r.run,
                         r.iterations, r.solid_request, r.solid_reply, r.fluid_request, r.fluid_reply, r.solid_med,
                         r.solid_p99, r.fluid_med, r.fluid_p99, r.iter_med, r.iter_p99, r.codec_med);
  }
}

}  // namespace

int main(int argc, char** argv) {
  fsi::init_process();  // as the real executables do
  // 1. Parse options.
  CLI::App app{"Messaging cost per coupling iteration (solid + fluid round trip over tcp loopback)"};
  std::vector<int> nodes{100, 1000, 10000}, iterations{2000, 2000, 300};
  int warmup = 200, runs = 1;
  double timeout_s = 10;
  std::string out_path;
  app.set_version_flag("--version", fsi::version_line("bench_messaging") + "\nprotocol fsi.v1, version " +
                                        std::to_string(fsi::protocol::kProtocolVersion));
  app.add_option("--nodes", nodes, "interface node counts")->expected(1, -1);
  app.add_option("--iterations", iterations, "timed coupling iterations per node count (one value = all)")
      ->expected(1, -1);
  app.add_option("--warmup", warmup, "untimed coupling iterations before each measurement")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--runs", runs, "repeat each measurement; the last row per size is the median of the runs")
      ->check(CLI::PositiveNumber);
  app.add_option("--timeout", timeout_s, "seconds to wait for any reply or for a server to start")
      ->check(CLI::PositiveNumber);
  app.add_option("--out", out_path, "also write the rows to this file (.json = JSON, else CSV)");
  CLI11_PARSE(app, argc, argv);
  if (iterations.size() != 1 && iterations.size() != nodes.size()) {
    fmt::print(stderr, "--iterations needs one value or one per --nodes value\n");
    return 1;
  }
  for (int n : nodes)
    if (n < 1) return fmt::print(stderr, "--nodes values must be >= 1\n"), 1;
  for (int it : iterations)
    if (it < 1) return fmt::print(stderr, "--iterations values must be >= 1\n"), 1;

  // 2. Start the two servers (fork before anything touches ZeroMQ), then measure.
  const auto timeout = milliseconds(static_cast<long>(timeout_s * 1000));
  std::signal(SIGPIPE, SIG_IGN);
  std::vector<Row> rows;
  int code = 0;
  try {
    ChildServer solid_child("solid", timeout);
    ChildServer fluid_child("fluid", timeout);
    {
      fsi::protocol::RemoteSolid solid(
          std::make_unique<fsi::protocol::ProtocolClient>(solid_child.endpoint(), "echo solid server", timeout));
      fsi::protocol::RemoteFluid fluid(
          std::make_unique<fsi::protocol::ProtocolClient>(fluid_child.endpoint(), "echo fluid server", timeout));
      fmt::print("servers: '{}' at {}, '{}' at {}; warm-up {} iterations, {} run(s)\n", solid.name(),
                 solid_child.endpoint(), fluid.name(), fluid_child.endpoint(), warmup, runs);
      for (std::size_t i = 0; i < nodes.size(); ++i) {
        const int iters = iterations.size() == 1 ? iterations[0] : iterations[i];
        std::vector<Row> per_run;
        for (int r = 1; r <= runs; ++r) {
          Row row = measure(solid, fluid, nodes[i], warmup, iters);
          row.run = std::to_string(r);
          fmt::print("  {:>6} nodes, run {}: coupling iteration median {:.0f} us, p99 {:.0f} us\n", row.nodes, r,
                     row.iter_med, row.iter_p99);
          std::fflush(stdout);
          per_run.push_back(row);
        }
        rows.insert(rows.end(), per_run.begin(), per_run.end());
        if (runs > 1) rows.push_back(median_of(per_run));
      }
      // A failed Stop is only a warning: the measurement is done and the children are
      // killed and reaped below anyway.
      for (auto [name, stop] : {std::pair<const char*, std::function<void()>>{"solid", [&] { solid.stop("done"); }},
                                {"fluid", [&] { fluid.stop("done"); }}}) {
        try {
          stop();
        } catch (const std::exception& e) {
          fmt::print(stderr, "warning: stopping the {} server: {}\n", name, e.what());
        }
      }
    }
    const int s = solid_child.finish(milliseconds(3000)), f = fluid_child.finish(milliseconds(3000));
    if (s != 0 || f != 0) fmt::print(stderr, "warning: servers exited with codes {} (solid) and {} (fluid)\n", s, f);
  } catch (const std::exception& e) {
    fmt::print(stderr, "bench_messaging: {}\n", e.what());
    code = 1;
  }
  if (rows.empty()) return code ? code : 1;

  // 3. Report.
  print_table(rows);
  fmt::print(
      "\nbytes: protobuf payload per message (ZeroMQ adds a few bytes of framing); round trip = "
      "RemoteSolid/RemoteFluid::solve_step as the coupler calls it (Eigen <-> protobuf, "
      "serialise, send, server parse + echo + serialise, receive, parse, checks); protocol (no sockets) = the same "
      "encode/decode and service work for one coupling iteration in-process, to separate it from the transport\n");
  if (!out_path.empty()) {
    try {
      write_out(out_path, rows);
      fmt::print("wrote {}\n", out_path);
    } catch (const std::exception& e) {
      fmt::print(stderr, "bench_messaging: {}\n", e.what());
      code = 1;
    }
  }
  return code;
}
