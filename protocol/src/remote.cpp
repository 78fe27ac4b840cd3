#include "fsi/protocol/remote.hpp"

#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>

#include "fsi/common/utf8.hpp"

namespace fsi::protocol {

Eigen::VectorXd to_eigen(const google::protobuf::RepeatedField<double>& field) {
  Eigen::VectorXd v(field.size());
  for (int i = 0; i < field.size(); ++i) v[i] = field.Get(i);
  return v;
}

void from_eigen(const Eigen::VectorXd& v, google::protobuf::RepeatedField<double>* field) {
  field->Resize(static_cast<int>(v.size()), 0.0);
  for (Eigen::Index i = 0; i < v.size(); ++i) field->Set(static_cast<int>(i), v[i]);
}

void nodal_to_proto(const NodalMatrix& m, fsi::v1::NodalMatrix* out) {
  out->Clear();
  out->set_size(static_cast<unsigned>(m.rows()));
  for (int col = 0; col < m.outerSize(); ++col)
    for (NodalMatrix::InnerIterator it(m, col); it; ++it) {
      out->add_rows(static_cast<unsigned>(it.row()));
      out->add_cols(static_cast<unsigned>(it.col()));
      out->add_values(it.value());
    }
}

NodalMatrix nodal_from_proto(const fsi::v1::NodalMatrix& m, std::size_t n, const std::string& what) {
  if (m.size() != n)
    throw std::invalid_argument(fmt::format("{}: size {}, expected {} (interface nodes)", what, m.size(), n));
  if (m.rows_size() != m.values_size() || m.cols_size() != m.values_size())
    throw std::invalid_argument(fmt::format("{}: {} rows, {} cols and {} values (must be equal)", what, m.rows_size(),
                                            m.cols_size(), m.values_size()));
  std::vector<Eigen::Triplet<double>> t;
  t.reserve(static_cast<std::size_t>(m.values_size()));
  for (int k = 0; k < m.values_size(); ++k) {
    if (m.rows(k) >= n || m.cols(k) >= n)
      throw std::invalid_argument(
          fmt::format("{}: entry {} at ({}, {}) is outside {} x {}", what, k, m.rows(k), m.cols(k), n, n));
    if (!std::isfinite(m.values(k)))
      throw std::invalid_argument(fmt::format("{}: entry {} at ({}, {}) is not finite", what, k, m.rows(k), m.cols(k)));
    t.emplace_back(static_cast<int>(m.rows(k)), static_cast<int>(m.cols(k)), m.values(k));
  }
  NodalMatrix out(static_cast<Eigen::Index>(n), static_cast<Eigen::Index>(n));
  out.setFromTriplets(t.begin(), t.end());
  return out;
}

InterfaceMeshData interface_from_proto(const fsi::v1::InterfaceMesh& mesh) {
  InterfaceMeshData data;
  const unsigned dim_field = mesh.dimension();
  if (dim_field != 0 && dim_field != 2 && dim_field != 3)
    throw std::invalid_argument(fmt::format("interface mesh: dimension {} (must be 2 or 3; absent = 2)", dim_field));
  const int d = dim_field == 3 ? 3 : 2;
  data.dimension = d;
  if (mesh.coordinates_size() % d != 0)
    throw std::invalid_argument(fmt::format("interface mesh: {} coordinates is not a multiple of {} (dimension {})",
                                            mesh.coordinates_size(), d, d));
  const int n = mesh.coordinates_size() / d;
  if (n == 0) throw std::invalid_argument("interface mesh: no nodes (coordinates is empty)");
  static const char* axis[] = {"x", "y", "z"};
  for (int i = 0; i < mesh.coordinates_size(); ++i)
    if (!std::isfinite(mesh.coordinates(i)))
      throw std::invalid_argument(
          fmt::format("interface mesh: coordinate {} of node {} is not finite", axis[i % d], i / d));
  data.coordinates.resize(n, d);
  for (int i = 0; i < n; ++i)
    for (int c = 0; c < d; ++c) data.coordinates(i, c) = mesh.coordinates(d * i + c);
  data.node_ids.assign(mesh.node_ids().begin(), mesh.node_ids().end());
  if (data.node_ids.empty())
    for (int i = 0; i < n; ++i) data.node_ids.push_back(i);
  if (static_cast<int>(data.node_ids.size()) != n)
    throw std::invalid_argument(fmt::format("interface mesh: {} node ids for {} nodes", data.node_ids.size(), n));
  {
    auto ids = data.node_ids;
    std::sort(ids.begin(), ids.end());
    const auto dup = std::adjacent_find(ids.begin(), ids.end());
    if (dup != ids.end()) throw std::invalid_argument(fmt::format("interface mesh: node id {} appears twice", *dup));
  }
  if (d == 3 && mesh.segments_size() > 0)
    throw std::invalid_argument("interface mesh: segments in a 3D interface (3D interfaces are described by faces)");
  if (d == 2 && (mesh.faces_size() > 0 || mesh.face_sizes_size() > 0))
    throw std::invalid_argument("interface mesh: faces in a 2D interface (set dimension: 3, or send segments)");
  if (mesh.segments_size() % 2 != 0) throw std::invalid_argument("interface mesh: odd number of segment indices");
  for (int s = 0; s < mesh.segments_size() / 2; ++s) {
    const int a = static_cast<int>(mesh.segments(2 * s)), b = static_cast<int>(mesh.segments(2 * s + 1));
    if (a >= n || b >= n)
      throw std::invalid_argument(
          fmt::format("interface mesh: segment {} refers to node {} of {}", s, std::max(a, b), n));
    if (a == b) throw std::invalid_argument(fmt::format("interface mesh: segment {} joins node {} to itself", s, a));
    data.segments.push_back({a, b});
  }
  {
    int offset = 0;
    for (int f = 0; f < mesh.face_sizes_size(); ++f) {
      const unsigned size = mesh.face_sizes(f);
      if (size != 3 && size != 4 && size != 6 && size != 8 && size != 9)
        throw std::invalid_argument(
            fmt::format("interface mesh: face {} has {} nodes (3 or 6: triangle, 4, 8 or 9: quadrilateral)", f, size));
      if (offset + static_cast<int>(size) > mesh.faces_size())
        throw std::invalid_argument(fmt::format("interface mesh: face {} needs {} indices, {} are left in faces", f,
                                                size, mesh.faces_size() - offset));
      InterfaceFace face;
      for (unsigned k = 0; k < size; ++k) {
        const unsigned v = mesh.faces(offset + static_cast<int>(k));
        if (v >= static_cast<unsigned>(n))
          throw std::invalid_argument(fmt::format("interface mesh: face {} refers to node {} of {}", f, v, n));
        face.nodes.push_back(static_cast<int>(v));
      }
      auto sorted = face.nodes;
      std::sort(sorted.begin(), sorted.end());
      if (std::adjacent_find(sorted.begin(), sorted.end()) != sorted.end())
        throw std::invalid_argument(fmt::format("interface mesh: face {} uses a node twice", f));
      offset += static_cast<int>(size);
      data.faces.push_back(std::move(face));
    }
    if (offset != mesh.faces_size())
      throw std::invalid_argument(
          fmt::format("interface mesh: face_sizes account for {} of {} face indices", offset, mesh.faces_size()));
  }
  data.lumped_measure = to_eigen(mesh.lumped_measure());
  if (data.points_only() && data.lumped_measure.size() != n && n > 0)
    throw std::invalid_argument(fmt::format("interface mesh: a point interface needs one lumped_measure per node{}",
                                            d == 3 ? " (or faces)" : ""));
  if (data.lumped_measure.size() != 0 && data.lumped_measure.size() != n)
    throw std::invalid_argument(
        fmt::format("interface mesh: {} lumped_measure values for {} nodes", data.lumped_measure.size(), n));
  for (Eigen::Index i = 0; i < data.lumped_measure.size(); ++i)
    if (!(std::isfinite(data.lumped_measure[i]) && data.lumped_measure[i] > 0))
      throw std::invalid_argument(
          fmt::format("interface mesh: lumped_measure of node {} is {} (must be finite and "
                      "> 0: a negative measure turns Algorithm 2's damping into a source)",
                      i, data.lumped_measure[i]));
  data.initial_displacement = to_eigen(mesh.initial_displacement());
  data.initial_velocity = to_eigen(mesh.initial_velocity());
  data.mass_per_area = mesh.mass_per_area();
  if (!(std::isfinite(data.mass_per_area) && data.mass_per_area >= 0))
    throw std::invalid_argument(
        fmt::format("interface mesh: mass_per_area is {} (must be finite and >= 0)", data.mass_per_area));
  for (const auto& [what, v] :
       {std::pair<const char*, const Eigen::VectorXd*>{"initial_displacement", &data.initial_displacement},
        {"initial_velocity", &data.initial_velocity}}) {
    if (v->size() != 0 && v->size() != d * n)
      throw std::invalid_argument(
          fmt::format("interface mesh: {} has {} values, expected 0 or {}", what, v->size(), d * n));
    for (Eigen::Index i = 0; i < v->size(); ++i)
      if (!std::isfinite((*v)[i]))
        throw std::invalid_argument(fmt::format("interface mesh: {} of node {} is not finite", what, i / d));
  }
  return data;
}

void interface_to_proto(const InterfaceMeshData& data, fsi::v1::InterfaceMesh* mesh) {
  for (auto id : data.node_ids) mesh->add_node_ids(id);
  for (Eigen::Index i = 0; i < data.coordinates.rows(); ++i)
    for (Eigen::Index c = 0; c < data.coordinates.cols(); ++c) mesh->add_coordinates(data.coordinates(i, c));
  for (const auto& s : data.segments) {
    mesh->add_segments(static_cast<unsigned>(s[0]));
    mesh->add_segments(static_cast<unsigned>(s[1]));
  }
  for (const auto& f : data.faces) {
    mesh->add_face_sizes(static_cast<unsigned>(f.nodes.size()));
    for (int v : f.nodes) mesh->add_faces(static_cast<unsigned>(v));
  }
  if (data.dimension != 2) mesh->set_dimension(static_cast<unsigned>(data.dimension));  // 2D sends nothing new
  from_eigen(data.lumped_measure, mesh->mutable_lumped_measure());
  from_eigen(data.initial_displacement, mesh->mutable_initial_displacement());
  from_eigen(data.initial_velocity, mesh->mutable_initial_velocity());
  mesh->set_mass_per_area(data.mass_per_area);
}

namespace {

fsi::v1::Request configure_request(const ConfigSection& section, double dt, double end_time,
                                   const std::string& output_dir) {
  fsi::v1::Request r;
  auto* c = r.mutable_configure();
  c->set_dt(dt);
  c->set_end_time(end_time);
  c->set_scene_text(section.scene_text());
  c->set_scene_path(section.scene_origin());
  for (const auto& o : section.scene_overrides()) c->add_overrides(o);
  c->set_section(section.path());
  c->set_output_dir(output_dir);
  return r;
}

// host:pid:start, the same for both servers of one coupler.
std::string session_name() {
  static const std::string name = [] {
    char host[256] = {0};
    gethostname(host, sizeof host - 1);
    return fmt::format(
        "{}:{}:{}", host, getpid(),
        std::chrono::duration_cast<std::chrono::milliseconds>(std::chrono::system_clock::now().time_since_epoch())
                .count() %
            100000000);
  }();
  return name;
}

std::string hello(ProtocolClient& client, fsi::v1::ServerKind expected, bool* supports_damping,
                  bool* supports_checkpoint, bool* supports_output, bool* supports_interface_mass = nullptr) {
  fsi::v1::Request r;
  r.mutable_hello()->set_client_name("fsi coupler");
  r.mutable_hello()->set_session(session_name());
  const auto reply = client.call(r);
  if (!reply.has_hello())
    throw RemoteError(fsi::v1::Error::MALFORMED, client.peer_name() + " did not answer the handshake with hello");
  if (reply.hello().kind() != expected)
    throw RemoteError(
        fsi::v1::Error::INVALID_ARGUMENT,
        fmt::format("{} at {} is a {} server, expected a {} server", client.peer_name(), client.endpoint(),
                    fsi::v1::ServerKind_Name(reply.hello().kind()), fsi::v1::ServerKind_Name(expected)));
  if (reply.hello().protocol_version() != kProtocolVersion)
    throw RemoteError(
        fsi::v1::Error::VERSION_MISMATCH,
        fmt::format("{} at {} speaks protocol version {} (HelloReply.protocol_version), this coupler {}",
                    client.peer_name(), client.endpoint(), reply.hello().protocol_version(), kProtocolVersion));
  if (reply.hello().server_name().empty())
    throw RemoteError(fsi::v1::Error::MALFORMED, fmt::format("{} at {} sent a HelloReply without server_name",
                                                             client.peer_name(), client.endpoint()));
  if (supports_damping) *supports_damping = reply.hello().supports_interface_damping();
  if (supports_interface_mass) *supports_interface_mass = reply.hello().supports_interface_mass();
  *supports_checkpoint = reply.hello().supports_checkpoint();
  *supports_output = reply.hello().supports_output();
  return reply.hello().server_name();
}

// A SolveStep request's step fields (time, dt, step, iteration); the caller adds the data.
fsi::v1::SolveStep* step_request(fsi::v1::Request& r, const StepInfo& info) {
  auto* s = r.mutable_solve_step();
  s->set_time(info.time);
  s->set_dt(info.dt);
  s->set_step(static_cast<unsigned>(info.step));
  s->set_iteration(static_cast<unsigned>(info.iteration));
  return s;
}

// A SolveStep's waveform (waveform iterations): the substeps, the sample times and the
// samples' vectors concatenated into `field`.
void window_request(fsi::v1::SolveStep* s, const Waveform& w, int substeps,
                    google::protobuf::RepeatedField<double>* field) {
  s->set_substeps(static_cast<unsigned>(substeps));
  for (std::size_t i = 0; i < w.times.size(); ++i) {
    s->add_sample_times(w.times[i]);
    for (Eigen::Index j = 0; j < w.values[i].size(); ++j) field->Add(w.values[i][j]);
  }
}

// `count` vectors of the interface's values, concatenated, checked as checked() does.
Eigen::VectorXd checked_samples(const google::protobuf::RepeatedField<double>& f, const InterfaceMeshData& mesh,
                                int count, const ProtocolClient& client, const char* what);

// A solver failure on the server side is a SolverError on this side (the run diverged),
// any other error reply stays a RemoteError (the run failed).
fsi::v1::Reply step_call(ProtocolClient& client, const fsi::v1::Request& r) {
  try {
    return client.call(r);
  } catch (const RemoteError& e) {
    if (e.code() == fsi::v1::Error::SOLVER_FAILED) throw SolverError(e.what());
    throw;
  }
}

void expect(bool ok, const ProtocolClient& client, const char* what) {
  if (!ok)
    throw RemoteError(fsi::v1::Error::MALFORMED, client.peer_name() + " answered with the wrong reply to " + what);
}

// GetInterface, checked: a valid mesh with the node count ConfigureReply announced.
InterfaceMeshData get_interface(ProtocolClient& client, std::uint32_t configured_nodes) {
  fsi::v1::Request g;
  g.mutable_get_interface();
  const auto reply = client.call(g);
  expect(reply.has_interface(), client, "get_interface");
  InterfaceMeshData data;
  try {
    data = interface_from_proto(reply.interface());
  } catch (const std::invalid_argument& e) {
    throw RemoteError(fsi::v1::Error::INVALID_ARGUMENT,
                      fmt::format("{} sent an invalid {}", client.peer_name(), e.what()));
  }
  if (configured_nodes != 0 && configured_nodes != data.nodes())
    throw RemoteError(fsi::v1::Error::INVALID_ARGUMENT,
                      fmt::format("{} announced {} interface nodes (ConfigureReply.interface_nodes) but its "
                                  "interface mesh has {}",
                                  client.peer_name(), configured_nodes, data.nodes()));
  return data;
}

Eigen::VectorXd checked(const google::protobuf::RepeatedField<double>& f, const InterfaceMeshData& mesh,
                        const ProtocolClient& client, const char* what) {
  const std::size_t expected = mesh.values();
  if (static_cast<std::size_t>(f.size()) != expected)
    throw RemoteError(fsi::v1::Error::INVALID_ARGUMENT,
                      fmt::format("{} sent {} values for '{}', expected {} ({} nodes x {})", client.peer_name(),
                                  f.size(), what, expected, mesh.nodes(), mesh.dimension));
  Eigen::VectorXd v = to_eigen(f);
  for (Eigen::Index i = 0; i < v.size(); ++i)
    if (!std::isfinite(v[i]))
      throw SolverError(
          fmt::format("{} sent a non-finite '{}' at node {}", client.peer_name(), what, i / mesh.dimension));
  return v;
}

Eigen::VectorXd checked_samples(const google::protobuf::RepeatedField<double>& f, const InterfaceMeshData& mesh,
                                int count, const ProtocolClient& client, const char* what) {
  const std::size_t expected = mesh.values() * static_cast<std::size_t>(count);
  if (static_cast<std::size_t>(f.size()) != expected)
    throw RemoteError(fsi::v1::Error::INVALID_ARGUMENT,
                      fmt::format("{} sent {} values for '{}', expected {} ({} substeps x {} nodes x {})",
                                  client.peer_name(), f.size(), what, expected, count, mesh.nodes(), mesh.dimension));
  Eigen::VectorXd v = to_eigen(f);
  if (!v.allFinite()) throw SolverError(fmt::format("{} sent a non-finite '{}'", client.peer_name(), what));
  return v;
}

// Calls both remote models make the same way.
std::map<std::string, double> accept_call(ProtocolClient& client, const StepInfo& info,
                                          std::map<std::string, double>& timings,
                                          std::map<std::string, double>& diagnostics) {
  fsi::v1::Request r;
  r.mutable_accept_step()->set_time(info.time);
  r.mutable_accept_step()->set_step(static_cast<unsigned>(info.step));
  const auto reply = client.call(r);
  expect(reply.has_accept(), client, "accept_step");
  for (const auto& [name, value] : reply.accept().probes())
    if (name.empty() || name.find_first_of(",\"\n\r ") != std::string::npos)
      throw RemoteError(fsi::v1::Error::INVALID_ARGUMENT,
                        fmt::format("{} sent a probe named '{}': probe names are column names of probes.csv "
                                    "(non-empty, no commas, quotes or spaces)",
                                    client.peer_name(), name));
  for (const auto& [name, value] : reply.accept().timings())
    if (!(std::isfinite(value) && value >= 0))
      throw RemoteError(
          fsi::v1::Error::INVALID_ARGUMENT,
          fmt::format("{} sent timing '{}' = {} (must be finite and >= 0)", client.peer_name(), name, value));
  timings = {reply.accept().timings().begin(), reply.accept().timings().end()};
  diagnostics = {reply.accept().diagnostics().begin(), reply.accept().diagnostics().end()};
  return {reply.accept().probes().begin(), reply.accept().probes().end()};
}

std::vector<std::string> output_call(ProtocolClient& client, const StepInfo& info) {
  fsi::v1::Request r;
  r.mutable_write_output()->set_time(info.time);
  r.mutable_write_output()->set_step(static_cast<unsigned>(info.step));
  const auto reply = client.call(r);
  expect(reply.has_output(), client, "write_output");
  return {reply.output().files().begin(), reply.output().files().end()};
}

std::string save_call(ProtocolClient& client, int step, double time) {
  fsi::v1::Request r;
  r.mutable_save_checkpoint()->set_step(static_cast<unsigned>(step));
  r.mutable_save_checkpoint()->set_time(time);
  const auto reply = client.call(r);
  expect(reply.has_checkpoint(), client, "save_checkpoint");
  if (reply.checkpoint().state().empty())
    throw RemoteError(
        fsi::v1::Error::INVALID_ARGUMENT,
        fmt::format("{} answered save_checkpoint of step {} with an empty state", client.peer_name(), step));
  return reply.checkpoint().state();
}

void load_call(ProtocolClient& client, int step, double time, const std::string& bytes) {
  fsi::v1::Request r;
  r.mutable_load_checkpoint()->set_step(static_cast<unsigned>(step));
  r.mutable_load_checkpoint()->set_time(time);
  r.mutable_load_checkpoint()->set_state(bytes);
  expect(client.call(r).has_loaded(), client, "load_checkpoint");
}

void stop_call(ProtocolClient& client, const std::string& reason) {
  fsi::v1::Request r;
  r.mutable_stop()->set_reason(fsi::valid_utf8(reason));
  client.set_timeout(std::chrono::seconds(2));
  client.call(r);
}

}  // namespace

// ---------------------------------------------------------------------------- solid
RemoteSolid::RemoteSolid(std::unique_ptr<ProtocolClient> client) : client_(std::move(client)) {
  server_name_ = hello(*client_, fsi::v1::SERVER_KIND_SOLID, &supports_damping_, &supports_checkpoint_,
                       &supports_output_, &supports_interface_mass_);
}

std::string RemoteSolid::save_checkpoint(int step, double time) { return save_call(*client_, step, time); }
void RemoteSolid::load_checkpoint(int step, double time, const std::string& bytes) {
  load_call(*client_, step, time, bytes);
}

void RemoteSolid::configure(const ConfigSection& section, const SolidSetup& setup) {
  auto r = configure_request(section, setup.dt, setup.end_time, setup.output_dir.string());
  r.mutable_configure()->set_interface_damping(setup.interface_damping);
  const auto configured = client_->call(r);
  expect(configured.has_configure(), *client_, "configure");
  interface_ = get_interface(*client_, configured.configure().interface_nodes());
  supports_substeps_ = configured.configure().supports_substeps();
}

SolidStepResult RemoteSolid::solve_window(const StepInfo& info, const Waveform& force, int substeps) {
  fsi::v1::Request r;
  auto* s = step_request(r, info);
  window_request(s, force, substeps, s->mutable_interface_force());
  if (send_interface_mass_) nodal_to_proto(interface_mass_, s->mutable_interface_mass());
  const auto reply = step_call(*client_, r);
  send_interface_mass_ = false;
  expect(reply.has_solid_step(), *client_, "solve_step");
  const auto& step = reply.solid_step();
  SolidStepResult out;
  out.interface_displacement = checked(step.interface_displacement(), interface_, *client_, "interface_displacement");
  out.interface_velocity = checked(step.interface_velocity(), interface_, *client_, "interface_velocity");
  out.displacement_samples =
      checked_samples(step.displacement_samples(), interface_, substeps, *client_, "displacement_samples");
  out.velocity_samples = checked_samples(step.velocity_samples(), interface_, substeps, *client_, "velocity_samples");
  out.newton_iterations = static_cast<int>(step.newton_iterations());
  return out;
}

SolidStepResult RemoteSolid::solve_step(const StepInfo& info, const Eigen::VectorXd& force) {
  fsi::v1::Request r;
  auto* s = step_request(r, info);
  from_eigen(force, s->mutable_interface_force());
  if (send_interface_mass_) nodal_to_proto(interface_mass_, s->mutable_interface_mass());
  const auto reply = step_call(*client_, r);
  send_interface_mass_ = false;
  expect(reply.has_solid_step(), *client_, "solve_step");
  SolidStepResult out;
  out.interface_displacement =
      checked(reply.solid_step().interface_displacement(), interface_, *client_, "interface_displacement");
  out.interface_velocity = checked(reply.solid_step().interface_velocity(), interface_, *client_, "interface_velocity");
  out.newton_iterations = static_cast<int>(reply.solid_step().newton_iterations());
  return out;
}

std::map<std::string, double> RemoteSolid::accept_step(const StepInfo& info) {
  return accept_call(*client_, info, timings_, diagnostics_);
}

std::vector<std::string> RemoteSolid::write_output(const StepInfo& info) { return output_call(*client_, info); }

void RemoteSolid::stop(const std::string& reason) { stop_call(*client_, reason); }

// ---------------------------------------------------------------------------- fluid
RemoteFluid::RemoteFluid(std::unique_ptr<ProtocolClient> client) : client_(std::move(client)) {
  server_name_ = hello(*client_, fsi::v1::SERVER_KIND_FLUID, nullptr, &supports_checkpoint_, &supports_output_);
}

std::string RemoteFluid::save_checkpoint(int step, double time) { return save_call(*client_, step, time); }
void RemoteFluid::load_checkpoint(int step, double time, const std::string& bytes) {
  load_call(*client_, step, time, bytes);
}

void RemoteFluid::configure(const ConfigSection& section, const FluidSetup& setup) {
  auto r = configure_request(section, setup.dt, setup.end_time, setup.output_dir.string());
  r.mutable_configure()->set_nitsche_penalty(setup.nitsche_penalty);
  r.mutable_configure()->set_nitsche_symmetry(setup.nitsche_symmetry);
  const auto configured = client_->call(r);
  expect(configured.has_configure(), *client_, "configure");
  interface_ = get_interface(*client_, configured.configure().interface_nodes());
  supports_robin_ = configured.configure().supports_robin();
  supports_substeps_ = configured.configure().supports_substeps();
}

namespace {
FluidLoads loads_from(const fsi::v1::Reply& reply, const InterfaceMeshData& mesh, const ProtocolClient& client) {
  expect(reply.has_fluid_loads(), client, "a fluid solve");
  FluidLoads out;
  const std::size_t n = mesh.nodes();
  out.traction_force = checked(reply.fluid_loads().traction_force(), mesh, client, "traction_force");
  out.velocity_integral = checked(reply.fluid_loads().velocity_integral(), mesh, client, "velocity_integral");
  out.nonlinear_iterations = static_cast<int>(reply.fluid_loads().nonlinear_iterations());
  if (reply.fluid_loads().has_interface_mass()) {
    try {
      out.interface_mass = nodal_from_proto(reply.fluid_loads().interface_mass(), n, "interface_mass");
    } catch (const std::invalid_argument& e) {
      throw RemoteError(fsi::v1::Error::INVALID_ARGUMENT, fmt::format("{} sent {}", client.peer_name(), e.what()));
    }
  }
  return out;
}
}  // namespace

FluidLoads RemoteFluid::initial_loads(const Eigen::VectorXd& d, const Eigen::VectorXd& v) {
  fsi::v1::Request r;
  from_eigen(d, r.mutable_initial_loads()->mutable_interface_displacement());
  from_eigen(v, r.mutable_initial_loads()->mutable_interface_velocity());
  return loads_from(client_->call(r), interface_, *client_);
}

FluidLoads RemoteFluid::solve_step(const StepInfo& info, const Eigen::VectorXd& d, const Eigen::VectorXd& v) {
  fsi::v1::Request r;
  auto* s = step_request(r, info);
  from_eigen(d, s->mutable_interface_displacement());
  from_eigen(v, s->mutable_interface_velocity());
  return loads_from(step_call(*client_, r), interface_, *client_);
}

FluidLoads RemoteFluid::solve_window(const StepInfo& info, const Waveform& d, const Waveform& v, int substeps) {
  fsi::v1::Request r;
  auto* s = step_request(r, info);
  window_request(s, d, substeps, s->mutable_interface_displacement());
  for (const auto& value : v.values)
    for (Eigen::Index j = 0; j < value.size(); ++j) s->add_interface_velocity(value[j]);
  const auto reply = step_call(*client_, r);
  FluidLoads out = loads_from(reply, interface_, *client_);
  out.traction_samples =
      checked_samples(reply.fluid_loads().traction_samples(), interface_, substeps, *client_, "traction_samples");
  out.velocity_integral_samples = checked_samples(reply.fluid_loads().velocity_integral_samples(), interface_, substeps,
                                                  *client_, "velocity_integral_samples");
  return out;
}

FluidLoads RemoteFluid::solve_robin(const StepInfo& info, const Eigen::VectorXd& d, const RobinCondition& robin) {
  fsi::v1::Request r;
  auto* s = step_request(r, info);
  from_eigen(d, s->mutable_interface_displacement());
  from_eigen(robin.coefficient, s->mutable_robin()->mutable_coefficient());
  from_eigen(robin.velocity, s->mutable_robin()->mutable_velocity());
  from_eigen(robin.traction, s->mutable_robin()->mutable_traction());
  return loads_from(step_call(*client_, r), interface_, *client_);
}

std::map<std::string, double> RemoteFluid::accept_step(const StepInfo& info) {
  return accept_call(*client_, info, timings_, diagnostics_);
}

std::vector<std::string> RemoteFluid::write_output(const StepInfo& info) { return output_call(*client_, info); }

void RemoteFluid::stop(const std::string& reason) { stop_call(*client_, reason); }

}  // namespace fsi::protocol
