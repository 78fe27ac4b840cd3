#include "fsi/protocol/service.hpp"

#include <fmt/format.h>
#include <google/protobuf/io/coded_stream.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <climits>
#include <csignal>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <optional>

#include "fsi/common/log.hpp"
#include "fsi/common/utf8.hpp"
#include "fsi/protocol/client.hpp"
#include "fsi/protocol/remote.hpp"
#include "fsi/transport/transport.hpp"

namespace fsi::protocol {
namespace {

void set_error(fsi::v1::Reply& reply, fsi::v1::Error::Code code, const std::string& message) {
  reply.clear_body();
  reply.mutable_error()->set_code(code);
  reply.mutable_error()->set_message(fsi::valid_utf8(message));  // else the reply would not parse
}

// The request's body (its field number in Request and its length), read from the wire before
// parsing: requests without bulk data have a size limit, so a huge Hello is refused without
// the memory its parse would take. Nothing when the bytes do not look like a Request (the
// parser then says what is wrong).
std::optional<std::pair<int, std::uint64_t>> peek_body(const std::string& bytes) {
  google::protobuf::io::CodedInputStream in(reinterpret_cast<const std::uint8_t*>(bytes.data()),
                                            static_cast<int>(std::min<std::size_t>(bytes.size(), INT32_MAX)));
  while (true) {
    const std::uint32_t tag = in.ReadTag();
    if (tag == 0) return std::nullopt;
    const int field = static_cast<int>(tag >> 3), wire = static_cast<int>(tag & 7);
    std::uint64_t value = 0;
    if (wire == 0) {  // protocol_version, sequence
      if (!in.ReadVarint64(&value)) return std::nullopt;
    } else if (wire == 2) {
      std::uint32_t length = 0;
      if (!in.ReadVarint32(&length)) return std::nullopt;
      if (field >= 10) return std::make_pair(field, static_cast<std::uint64_t>(length));
      if (!in.Skip(static_cast<int>(length))) return std::nullopt;
    } else {
      return std::nullopt;
    }
  }
}

// Request kinds that carry no bulk data, and the size a request of that kind may have.
constexpr std::size_t kSmallRequestLimit = 1u << 20;       // hello, get_interface, accept, output, stop, save
constexpr std::size_t kConfigureRequestLimit = 64u << 20;  // a scene's text and overrides
std::optional<std::pair<const char*, std::size_t>> request_limit(int field) {
  switch (field) {
    case 10:
      return std::make_pair("hello", kSmallRequestLimit);
    case 11:
      return std::make_pair("configure", kConfigureRequestLimit);
    case 12:
      return std::make_pair("get_interface", kSmallRequestLimit);
    case 14:
      return std::make_pair("accept_step", kSmallRequestLimit);
    case 15:
      return std::make_pair("write_output", kSmallRequestLimit);
    case 16:
      return std::make_pair("stop", kSmallRequestLimit);
    case 18:
      return std::make_pair("save_checkpoint", kSmallRequestLimit);
    default:
      return std::nullopt;  // solve_step, initial_loads, load_checkpoint: interface data and states
  }
}

// Checks a received vector: expected size and every entry finite.
const char* axis_name(int component) {
  static const char* names[] = {"x", "y", "z"};
  return names[component];
}

// Checks a received vector: `dim` values per interface node and every entry finite.
Eigen::VectorXd checked_vector(const google::protobuf::RepeatedField<double>& field, std::size_t nodes, int dim,
                               const char* name) {
  const std::size_t expected = nodes * static_cast<std::size_t>(dim);
  if (static_cast<std::size_t>(field.size()) != expected)
    throw std::invalid_argument(
        fmt::format("'{}' has {} values, expected {} ({} per interface node)", name, field.size(), expected, dim));
  for (int i = 0; i < field.size(); ++i)
    if (!std::isfinite(field.Get(i)))
      throw std::invalid_argument(fmt::format("'{}' value {} (node {}, component {}) is not finite: {}", name, i,
                                              i / dim, axis_name(i % dim), field.Get(i)));
  return to_eigen(field);
}

// The step of a solve_step request: dt positive and the time finite (a model divides by dt).
StepInfo checked_step(const fsi::v1::SolveStep& s) {
  if (!(s.dt() > 0) || !std::isfinite(s.dt()))
    throw std::invalid_argument(fmt::format("solve_step: dt must be positive, got {}", s.dt()));
  if (!std::isfinite(s.time()))
    throw std::invalid_argument(fmt::format("solve_step: time must be finite, got {}", s.time()));
  return {s.time(), s.dt(), static_cast<int>(s.step()), static_cast<int>(s.iteration())};
}

// A SolveStep's waveform (SolveStep.substeps > 1): sample_times, increasing, from the window's
// start to `time`, and one interface vector per sample in `field`.
Waveform checked_waveform(const fsi::v1::SolveStep& s, const google::protobuf::RepeatedField<double>& field,
                          std::size_t nodes, int dim, const char* name) {
  const int count = s.sample_times_size();
  if (count < 2)
    throw std::invalid_argument(
        fmt::format("solve_step: substeps {} needs sample_times (at least the window's start "
                    "and end), got {}",
                    s.substeps(), count));
  Waveform w;
  for (int i = 0; i < count; ++i) {
    if (!std::isfinite(s.sample_times(i)) || (i > 0 && !(s.sample_times(i) > s.sample_times(i - 1))))
      throw std::invalid_argument("solve_step: sample_times must be finite and increasing");
    w.times.push_back(s.sample_times(i));
  }
  const std::size_t m = nodes * static_cast<std::size_t>(dim);
  if (static_cast<std::size_t>(field.size()) != m * static_cast<std::size_t>(count))
    throw std::invalid_argument(fmt::format("'{}' has {} values, expected {} ({} samples x {} per sample)", name,
                                            field.size(), m * count, count, m));
  const Eigen::VectorXd all = to_eigen(field);
  if (!all.allFinite()) throw std::invalid_argument(fmt::format("'{}' has a value that is not finite", name));
  for (int i = 0; i < count; ++i) w.values.push_back(all.segment(static_cast<Eigen::Index>(i * m), m));
  return w;
}

// A solver section's substeps, read (so the key counts as used) and checked against the model.
int configured_substeps(const ConfigSection& section, bool supported, const std::string& model) {
  const int n = substeps_of(section);
  if (n > 1 && !supported)
    throw RemoteError(fsi::v1::Error::UNSUPPORTED,
                      fmt::format("{}.substeps: {} needs a model that takes substeps (waveform iterations); '{}' "
                                  "does not (set {}.substeps: 1)",
                                  section.path(), n, model, section.path()));
  return n;
}

void require_finite(const Eigen::VectorXd& v, int dim, const std::string& what) {
  for (Eigen::Index i = 0; i < v.size(); ++i)
    if (!std::isfinite(v[i]))
      throw SolverError(fmt::format("{} produced a non-finite value at node {} ({}): {}", what, i / dim,
                                    axis_name(static_cast<int>(i % dim)), v[i]));
}

Scene scene_from(const fsi::v1::Configure& c) {
  std::vector<std::string> overrides(c.overrides().begin(), c.overrides().end());
  return Scene::parse(c.scene_text(), c.scene_path().empty() ? "<scene>" : c.scene_path(), overrides);
}

// The requests a solid and a fluid service answer the same way. Returns false for others.
template <class Model>
bool handle_shared(const fsi::v1::Request& request, fsi::v1::Reply& reply, bool& stop, Model* model, double dt,
                   const std::string& not_configured) {
  using R = fsi::v1::Request;
  const auto body = request.body_case();
  if (body == R::kStop) {
    reply.mutable_stop();
    stop = true;
    return true;
  }
  if (body != R::kGetInterface && body != R::kAcceptStep && body != R::kWriteOutput && body != R::kSaveCheckpoint &&
      body != R::kLoadCheckpoint)
    return false;
  if (!model) throw RemoteError(fsi::v1::Error::BAD_SEQUENCE, not_configured);
  if (body == R::kGetInterface) {
    interface_to_proto(model->interface(), reply.mutable_interface());
  } else if (body == R::kAcceptStep) {
    const StepInfo info{request.accept_step().time(), dt, static_cast<int>(request.accept_step().step()), 0};
    auto* out = reply.mutable_accept();
    for (const auto& [k, v] : model->accept_step(info)) (*out->mutable_probes())[fsi::valid_utf8(k)] = v;
    for (const auto& [k, v] : model->timings()) (*out->mutable_timings())[k] = v;
    for (const auto& [k, v] : model->diagnostics()) (*out->mutable_diagnostics())[fsi::valid_utf8(k)] = v;
  } else if (body == R::kSaveCheckpoint || body == R::kLoadCheckpoint) {
    if (!model->supports_checkpoint())
      throw RemoteError(fsi::v1::Error::UNSUPPORTED,
                        fmt::format("model '{}' does not support checkpoints", model->name()));
    if (body == R::kSaveCheckpoint) {
      StateArchive state;
      model->save_state(state);
      reply.mutable_checkpoint()->set_state(state.serialize());
    } else {
      const auto& l = request.load_checkpoint();
      try {
        model->load_state(StateArchive::parse(
            l.state(), fmt::format("checkpoint of step {} for model '{}'", l.step(), model->name())));
      } catch (const StateError& e) {
        throw std::invalid_argument(e.what());
      }
      reply.mutable_loaded();
    }
  } else {
    const StepInfo info{request.write_output().time(), dt, static_cast<int>(request.write_output().step()), 0};
    auto* out = reply.mutable_output();
    for (const auto& f : model->write_output(info)) out->add_files(f);
  }
  return true;
}

std::atomic<bool> g_signalled{false};
extern "C" void on_signal(int) { g_signalled = true; }

}  // namespace

void Service::peer_gone(const std::string& peer) {
  if (!session_open_ || peer != session_peer_) return;
  logger("server")->warn("session '{}' of '{}' ended: its connection closed", session_id_, session_client_);
  session_open_ = false;
  reset();
}

fsi::v1::Reply Service::handle(const fsi::v1::Request& request, bool& stop, const std::string& peer) {
  fsi::v1::Reply reply;
  reply.set_protocol_version(kProtocolVersion);
  reply.set_sequence(request.sequence());
  const auto start = std::chrono::steady_clock::now();
  // The order of checks: the version, then the session, then the body.
  if (request.protocol_version() != kProtocolVersion) {
    set_error(reply, fsi::v1::Error::VERSION_MISMATCH,
              fmt::format("protocol version mismatch: request has {}, this server speaks {}",
                          request.protocol_version(), kProtocolVersion));
    return reply;
  }
  if (session_open_ && peer != session_peer_) {
    set_error(reply, fsi::v1::Error::BUSY,
              fmt::format("this server is in session '{}' with '{}' (since {}); it serves one coupler at a time",
                          session_id_, session_client_, session_since_));
    return reply;
  }
  if (request.body_case() == fsi::v1::Request::BODY_NOT_SET) {
    set_error(reply, fsi::v1::Error::MALFORMED, "request has no body");
    return reply;
  }
  if (request.body_case() == fsi::v1::Request::kHello) {
    session_open_ = true;
    session_peer_ = peer;
    session_id_ = request.hello().session().empty() ? "unnamed" : request.hello().session();
    session_client_ = request.hello().client_name().empty() ? "a client" : request.hello().client_name();
    const auto now = std::chrono::system_clock::to_time_t(std::chrono::system_clock::now());
    char buf[32];
    std::strftime(buf, sizeof buf, "%H:%M:%S", std::localtime(&now));
    session_since_ = buf;
  }
  try {
    dispatch(request, reply, stop);
  } catch (const ConfigError& e) {
    set_error(reply, fsi::v1::Error::INVALID_ARGUMENT, e.what());
  } catch (const std::invalid_argument& e) {
    set_error(reply, fsi::v1::Error::INVALID_ARGUMENT, e.what());
  } catch (const SolverError& e) {
    set_error(reply, fsi::v1::Error::SOLVER_FAILED, e.what());
  } catch (const RemoteError& e) {
    set_error(reply, e.code(), e.what());
  } catch (const std::exception& e) {
    set_error(reply, fsi::v1::Error::INTERNAL, e.what());
  }
  if (request.body_case() == fsi::v1::Request::kConfigure)
    configure_failure_ = reply.has_error() ? reply.error().message() : std::string();
  reply.set_compute_seconds(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  return reply;
}

std::string Service::before_configure(const std::string& request) const {
  if (configure_failure_.empty()) return fmt::format("'{}' before 'configure'", request);
  return fmt::format("'{}' on an unconfigured server: the last 'configure' failed ({})", request, configure_failure_);
}

std::string Service::handle_bytes(const std::string& bytes, bool& stop, const std::string& peer) {
  if (const auto body = peek_body(bytes)) {
    if (const auto limit = request_limit(body->first); limit && bytes.size() > limit->second) {
      fsi::v1::Reply reply;
      reply.set_protocol_version(kProtocolVersion);
      set_error(reply, fsi::v1::Error::MALFORMED,
                fmt::format("a '{}' request of {} bytes exceeds the {} bytes such a request may have: refused "
                            "unread",
                            limit->first, bytes.size(), limit->second));
      return reply.SerializeAsString();
    }
  }
  fsi::v1::Request request;
  if (!request.ParseFromString(bytes)) {
    fsi::v1::Reply reply;
    reply.set_protocol_version(kProtocolVersion);
    set_error(reply, fsi::v1::Error::MALFORMED,
              fmt::format("message of {} bytes is not a fsi.v1.Request", bytes.size()));
    return reply.SerializeAsString();
  }
  return handle(request, stop, peer).SerializeAsString();
}

// ---------------------------------------------------------------------------- solid
SolidService::SolidService(SolidFactory factory, std::string server_name)
    : factory_(std::move(factory)), server_name_(std::move(server_name)) {}

void SolidService::dispatch(const fsi::v1::Request& request, fsi::v1::Reply& reply, bool& stop) {
  using R = fsi::v1::Request;
  if (handle_shared(request, reply, stop, model_.get(), dt_, before_configure(body_name(request)))) return;
  auto need_model = [&](const char* what) {
    if (!model_) throw RemoteError(fsi::v1::Error::BAD_SEQUENCE, before_configure(what));
  };
  switch (request.body_case()) {
    case R::kHello: {
      auto* h = reply.mutable_hello();
      h->set_kind(fsi::v1::SERVER_KIND_SOLID);
      h->set_server_name(server_name_);
      h->set_protocol_version(kProtocolVersion);
      h->set_supports_interface_damping(true);
      h->set_supports_interface_mass(true);
      h->set_supports_output(true);
      h->set_supports_checkpoint(true);
      break;
    }
    case R::kConfigure: {
      const auto& c = request.configure();
      model_.reset();  // a failed Configure leaves the server unconfigured, not with the old model
      interface_nodes_ = 0;
      if (!(c.dt() > 0) || !std::isfinite(c.dt()))
        throw std::invalid_argument(fmt::format("configure: dt must be positive, got {}", c.dt()));
      if (!std::isfinite(c.interface_damping()) || c.interface_damping() < 0)
        throw std::invalid_argument(
            fmt::format("configure: interface_damping must be finite and >= 0, got {}", c.interface_damping()));
      if (!std::isfinite(c.end_time()) || c.end_time() < 0)
        throw std::invalid_argument(fmt::format("configure: end_time must be finite and >= 0, got {}", c.end_time()));
      const Scene scene = scene_from(c);
      const auto section = scene.section(c.section().empty() ? "solid" : c.section());
      auto model = make_model(factory_, section, "solid");
      if (c.interface_damping() > 0 && !model->supports_interface_damping())
        throw RemoteError(fsi::v1::Error::UNSUPPORTED,
                          fmt::format("solid model '{}' cannot add interface damping (Algorithm 2)", model->name()));
      SolidSetup setup{c.dt(), c.end_time(), c.interface_damping(), c.output_dir(), read_vtk_format(scene)};
      model->configure(section, setup);
      configured_substeps(section, model->supports_substeps(), model->name());
      scene.check_all_used(section.path());
      model_ = std::move(model);
      interface_nodes_ = model_->interface().nodes();
      dimension_ = model_->interface().dimension;
      dt_ = c.dt();
      reply.mutable_configure()->set_interface_nodes(static_cast<unsigned>(interface_nodes_));
      reply.mutable_configure()->set_supports_substeps(model_->supports_substeps());
      break;
    }
    case R::kSolveStep: {
      need_model("solve_step");
      const auto& s = request.solve_step();
      const bool window = s.substeps() > 1;
      if (window && !model_->supports_substeps())
        throw RemoteError(fsi::v1::Error::UNSUPPORTED,
                          fmt::format("solid model '{}' does not take substeps (SolveStep.substeps)", model_->name()));
      const StepInfo info = checked_step(s);
      const Eigen::VectorXd force =
          window ? Eigen::VectorXd()
                 : checked_vector(s.interface_force(), interface_nodes_, dimension_, "interface_force");
      const Waveform force_samples =
          window ? checked_waveform(s, s.interface_force(), interface_nodes_, dimension_, "interface_force")
                 : Waveform();
      if (s.has_interface_mass())
        model_->set_interface_mass(nodal_from_proto(s.interface_mass(), interface_nodes_, "interface_mass"));
      const SolidStepResult result = window ? model_->solve_window(info, force_samples, static_cast<int>(s.substeps()))
                                            : model_->solve_step(info, force);
      require_finite(result.interface_displacement, dimension_, "solid step (displacement)");
      require_finite(result.interface_velocity, dimension_, "solid step (velocity)");
      auto* out = reply.mutable_solid_step();
      from_eigen(result.interface_displacement, out->mutable_interface_displacement());
      from_eigen(result.interface_velocity, out->mutable_interface_velocity());
      out->set_newton_iterations(result.newton_iterations);
      if (window) {
        require_finite(result.displacement_samples, dimension_, "solid step (displacement samples)");
        require_finite(result.velocity_samples, dimension_, "solid step (velocity samples)");
        from_eigen(result.displacement_samples, out->mutable_displacement_samples());
        from_eigen(result.velocity_samples, out->mutable_velocity_samples());
      }
      break;
    }
    default:
      throw RemoteError(fsi::v1::Error::UNSUPPORTED,
                        fmt::format("a solid server does not handle '{}'", body_name(request)));
  }
}

// ---------------------------------------------------------------------------- fluid
FluidService::FluidService(FluidFactory factory, std::string server_name)
    : factory_(std::move(factory)), server_name_(std::move(server_name)) {}

void FluidService::dispatch(const fsi::v1::Request& request, fsi::v1::Reply& reply, bool& stop) {
  using R = fsi::v1::Request;
  if (handle_shared(request, reply, stop, model_.get(), 0.0, before_configure(body_name(request)))) return;
  auto need_model = [&](const char* what) {
    if (!model_) throw RemoteError(fsi::v1::Error::BAD_SEQUENCE, before_configure(what));
  };
  auto loads_reply = [&](const FluidLoads& loads) {
    require_finite(loads.traction_force, dimension_, "fluid step (traction force)");
    require_finite(loads.velocity_integral, dimension_, "fluid step (velocity integral)");
    auto* out = reply.mutable_fluid_loads();
    from_eigen(loads.traction_force, out->mutable_traction_force());
    from_eigen(loads.velocity_integral, out->mutable_velocity_integral());
    out->set_nonlinear_iterations(loads.nonlinear_iterations);
    if (loads.interface_mass.rows() > 0) nodal_to_proto(loads.interface_mass, out->mutable_interface_mass());
    if (loads.traction_samples.size() > 0) {
      require_finite(loads.traction_samples, dimension_, "fluid step (traction samples)");
      require_finite(loads.velocity_integral_samples, dimension_, "fluid step (velocity integral samples)");
      from_eigen(loads.traction_samples, out->mutable_traction_samples());
      from_eigen(loads.velocity_integral_samples, out->mutable_velocity_integral_samples());
    }
  };
  switch (request.body_case()) {
    case R::kHello: {
      auto* h = reply.mutable_hello();
      h->set_kind(fsi::v1::SERVER_KIND_FLUID);
      h->set_server_name(server_name_);
      h->set_protocol_version(kProtocolVersion);
      h->set_supports_output(true);
      h->set_supports_checkpoint(true);
      break;
    }
    case R::kConfigure: {
      const auto& c = request.configure();
      model_.reset();  // a failed Configure leaves the server unconfigured, not with the old model
      interface_nodes_ = 0;
      if (!(c.dt() > 0) || !std::isfinite(c.dt()))
        throw std::invalid_argument(fmt::format("configure: dt must be positive, got {}", c.dt()));
      if (!std::isfinite(c.nitsche_penalty()) || c.nitsche_penalty() < 0)
        throw std::invalid_argument(
            fmt::format("configure: nitsche_penalty must be finite and >= 0, got {}", c.nitsche_penalty()));
      if (!std::isfinite(c.nitsche_symmetry()))
        throw std::invalid_argument(
            fmt::format("configure: nitsche_symmetry must be finite, got {}", c.nitsche_symmetry()));
      if (!std::isfinite(c.end_time()) || c.end_time() < 0)
        throw std::invalid_argument(fmt::format("configure: end_time must be finite and >= 0, got {}", c.end_time()));
      const Scene scene = scene_from(c);
      const auto section = scene.section(c.section().empty() ? "fluid" : c.section());
      auto model = make_model(factory_, section, "fluid");
      FluidSetup setup{c.dt(),         c.end_time(),          c.nitsche_penalty(), c.nitsche_symmetry(),
                       c.output_dir(), read_vtk_format(scene)};
      model->configure(section, setup);
      configured_substeps(section, model->supports_substeps(), model->name());
      scene.check_all_used(section.path());
      model_ = std::move(model);
      interface_nodes_ = model_->interface().nodes();
      dimension_ = model_->interface().dimension;
      reply.mutable_configure()->set_interface_nodes(static_cast<unsigned>(interface_nodes_));
      reply.mutable_configure()->set_supports_robin(model_->supports_robin());
      reply.mutable_configure()->set_supports_substeps(model_->supports_substeps());
      break;
    }
    case R::kInitialLoads: {
      need_model("initial_loads");
      const auto& s = request.initial_loads();
      loads_reply(model_->initial_loads(
          checked_vector(s.interface_displacement(), interface_nodes_, dimension_, "interface_displacement"),
          checked_vector(s.interface_velocity(), interface_nodes_, dimension_, "interface_velocity")));
      break;
    }
    case R::kSolveStep: {
      need_model("solve_step");
      const auto& s = request.solve_step();
      const StepInfo info = checked_step(s);
      if (s.has_robin()) {
        if (!model_->supports_robin())
          throw RemoteError(fsi::v1::Error::UNSUPPORTED,
                            fmt::format("fluid model '{}' does not take a Robin interface condition (SolveStep.robin)",
                                        model_->name()));
        const auto& rc = s.robin();
        loads_reply(model_->solve_robin(
            info, checked_vector(s.interface_displacement(), interface_nodes_, dimension_, "interface_displacement"),
            RobinCondition{checked_vector(rc.coefficient(), interface_nodes_, 1, "robin.coefficient"),
                           checked_vector(rc.velocity(), interface_nodes_, dimension_, "robin.velocity"),
                           checked_vector(rc.traction(), interface_nodes_, dimension_, "robin.traction")}));
        break;
      }
      if (s.substeps() > 1) {
        if (!model_->supports_substeps())
          throw RemoteError(
              fsi::v1::Error::UNSUPPORTED,
              fmt::format("fluid model '{}' does not take substeps (SolveStep.substeps)", model_->name()));
        const Waveform d =
            checked_waveform(s, s.interface_displacement(), interface_nodes_, dimension_, "interface_displacement");
        const Waveform v =
            checked_waveform(s, s.interface_velocity(), interface_nodes_, dimension_, "interface_velocity");
        const FluidLoads loads = model_->solve_window(info, d, v, static_cast<int>(s.substeps()));
        const auto m = static_cast<Eigen::Index>(interface_nodes_) * dimension_ * s.substeps();
        if (loads.traction_samples.size() != m || loads.velocity_integral_samples.size() != m)
          throw std::logic_error(
              fmt::format("fluid model '{}' returned no samples of its {} substeps", model_->name(), s.substeps()));
        loads_reply(loads);
        break;
      }
      loads_reply(model_->solve_step(
          info, checked_vector(s.interface_displacement(), interface_nodes_, dimension_, "interface_displacement"),
          checked_vector(s.interface_velocity(), interface_nodes_, dimension_, "interface_velocity")));
      break;
    }
    default:
      throw RemoteError(fsi::v1::Error::UNSUPPORTED,
                        fmt::format("a fluid server does not handle '{}'", body_name(request)));
  }
}

// ---------------------------------------------------------------------------- server loop
int run_server(Service& service, const std::string& endpoint, const std::string& port_file, double idle_timeout_seconds,
               const std::string& log_name, const transport::CurveKeys& keys) {
  auto log = logger(log_name);
  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);
  if (!keys.enabled() && endpoint.find("127.0.0.1") == std::string::npos &&
      endpoint.find("localhost") == std::string::npos && endpoint.find("[::1]") == std::string::npos)
    log->warn(
        "{} accepts any client that can reach it: use --curve-keys DIR (fsi keys DIR) beyond "
        "loopback",
        endpoint);
  transport::Server server(endpoint, keys);
  if (keys.enabled())
    log->info("CURVE: encrypted, {} authorised client key(s) from {}", keys.authorized.size(), keys.folder);
  const std::string bound = server.endpoint();
  if (!port_file.empty()) {
    const std::string tmp = port_file + ".tmp";
    { std::ofstream(tmp) << bound << '\n'; }
    std::filesystem::rename(tmp, port_file);
  }
  log->info("listening on {}", bound);
  server.set_disconnect_handler([&](const std::string& peer) { service.peer_gone(peer); });
  server.set_frame_error_handler([](std::size_t frames) {
    fsi::v1::Reply reply;
    reply.set_protocol_version(kProtocolVersion);
    set_error(reply, fsi::v1::Error::MALFORMED,
              fmt::format("message has {} frames after the envelope, expected exactly 1 (one serialised "
                          "fsi.v1.Request)",
                          frames));
    return reply.SerializeAsString();
  });
  const auto idle = std::chrono::milliseconds(static_cast<long>(idle_timeout_seconds * 1000));
  const bool clean = server.serve(
      [&](const std::string& bytes, const std::string& peer, bool& stop) {
        std::string reply = service.handle_bytes(bytes, stop, peer);
        return reply;
      },
      idle, [] { return g_signalled.load(); });
  if (g_signalled) {
    log->warn("interrupted by a signal, exiting");
    return 130;
  }
  if (!clean) {
    log->error("no request for {} s, exiting", idle_timeout_seconds);
    return 3;
  }
  log->info("stopped by the coupler");
  return 0;
}

}  // namespace fsi::protocol
