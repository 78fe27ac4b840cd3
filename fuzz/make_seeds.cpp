// Writes the request seeds of fuzz_solid_request and fuzz_fluid_request (valid sequences:
// hello -> configure -> get_interface -> solve_step x k -> accept_step -> write_output ->
// save_checkpoint -> load_checkpoint -> stop, for sdof, the FEM solid on a tiny rectangle and
// the surrogate fluid, plus a few out-of-order / invalid ones). The checkpoint bytes and the
// interface sizes come from running each sequence through a real service here.
//   fuzz_make_seeds fuzz/corpus      (writes seed_*.bin into <dir>/fuzz_*_request/)
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <string>
#include <vector>

#include "fsi/models/fluid_factory.hpp"
#include "fsi/models/solid_factory.hpp"
#include "request_harness.hpp"

namespace {
using fsi::v1::Request;

Request base(std::uint64_t seq) {
  Request r;
  r.set_protocol_version(fsi::protocol::kProtocolVersion);
  r.set_sequence(seq);
  return r;
}

std::string ser(const Request& r) { return r.SerializeAsString(); }

// Builds a sequence step by step, sending each request to `service` to learn sizes/states.
struct Builder {
  fsi::protocol::Service& service;
  std::vector<std::string> sent;
  std::uint64_t seq = 1;
  fsi::v1::Reply send(Request r) {
    r.set_sequence(seq++);
    const std::string bytes = ser(r);
    sent.push_back(bytes);
    bool stop = false;
    fsi::v1::Reply reply;
    reply.ParseFromString(service.handle_bytes(bytes, stop));
    if (reply.has_error()) std::fprintf(stderr, "  (reply error: %s)\n", reply.error().message().c_str());
    return reply;
  }
};

void write(const std::filesystem::path& dir, const std::string& name, const std::vector<std::string>& requests) {
  std::filesystem::create_directories(dir);
  std::ofstream(dir / (name + ".bin"), std::ios::binary) << fsi_fuzz::join_requests(requests);
}

Request hello() {
  auto r = base(0);
  r.mutable_hello()->set_client_name("fuzz seed");
  r.mutable_hello()->set_session("seed:1");
  return r;
}
Request configure(const std::string& scene, double dt, double damping, double penalty = 0) {
  auto r = base(0);
  auto* c = r.mutable_configure();
  c->set_dt(dt);
  c->set_end_time(10 * dt);
  c->set_scene_text(scene);
  c->set_scene_path("seed.yaml");
  c->set_interface_damping(damping);
  c->set_nitsche_penalty(penalty);
  c->set_nitsche_symmetry(-1);
  return r;
}
Request get_interface() {
  auto r = base(0);
  r.mutable_get_interface();
  return r;
}
Request accept(int step, double t) {
  auto r = base(0);
  r.mutable_accept_step()->set_step(step);
  r.mutable_accept_step()->set_time(t);
  return r;
}
Request output(int step, double t) {
  auto r = base(0);
  r.mutable_write_output()->set_step(step);
  r.mutable_write_output()->set_time(t);
  return r;
}
Request save(int step, double t) {
  auto r = base(0);
  r.mutable_save_checkpoint()->set_step(step);
  r.mutable_save_checkpoint()->set_time(t);
  return r;
}
Request load(int step, double t, const std::string& state) {
  auto r = base(0);
  r.mutable_load_checkpoint()->set_step(step);
  r.mutable_load_checkpoint()->set_time(t);
  r.mutable_load_checkpoint()->set_state(state);
  return r;
}
Request stop() {
  auto r = base(0);
  r.mutable_stop()->set_reason("done");
  return r;
}

// A full solid sequence: 2 steps of 2 coupling iterations, checkpoint after step 1, reload.
std::vector<std::string> solid_sequence(const std::string& scene, double damping, bool with_load = true) {
  fsi::protocol::SolidService service(fsi::models::make_solid_model, "seed");
  Builder b{service, {}};
  b.send(hello());
  const double dt = 0.01;
  b.send(configure(scene, dt, damping));
  const auto itf = b.send(get_interface());
  const int n = itf.interface().node_ids_size();
  std::string state;
  for (int step = 1; step <= 2; ++step) {
    for (int k = 1; k <= 2; ++k) {
      auto r = base(0);
      auto* s = r.mutable_solve_step();
      s->set_time(step * dt);
      s->set_dt(dt);
      s->set_step(step);
      s->set_iteration(k);
      for (int i = 0; i < n; ++i) s->add_interface_force(0.01 * k), s->add_interface_force(-0.02 * step);
      b.send(r);
    }
    b.send(accept(step, step * dt));
    b.send(output(step, step * dt));
    if (step == 1) state = b.send(save(1, dt)).checkpoint().state();
  }
  if (with_load) b.send(load(1, dt, state));
  b.send(stop());
  return b.sent;
}

std::vector<std::string> fluid_sequence(const std::string& scene) {
  fsi::protocol::FluidService service(fsi::models::make_fluid_model, "seed");
  Builder b{service, {}};
  b.send(hello());
  const double dt = 0.01;
  b.send(configure(scene, dt, 0, 10));
  const auto itf = b.send(get_interface());
  const int n = itf.interface().node_ids_size();
  {
    auto r = base(0);
    for (int i = 0; i < 2 * n; ++i)
      r.mutable_initial_loads()->add_interface_displacement(0), r.mutable_initial_loads()->add_interface_velocity(0);
    b.send(r);
  }
  std::string state;
  for (int step = 1; step <= 2; ++step) {
    for (int k = 1; k <= 2; ++k) {
      auto r = base(0);
      auto* s = r.mutable_solve_step();
      s->set_time(step * dt);
      s->set_dt(dt);
      s->set_step(step);
      s->set_iteration(k);
      for (int i = 0; i < n; ++i) {
        s->add_interface_displacement(0.001 * k), s->add_interface_displacement(0);
        s->add_interface_velocity(0.1 * step), s->add_interface_velocity(-0.1);
      }
      b.send(r);
    }
    b.send(accept(step, step * dt));
    b.send(output(step, step * dt));
    if (step == 1) state = b.send(save(1, dt)).checkpoint().state();
  }
  b.send(load(1, dt, state));
  b.send(stop());
  return b.sent;
}

const char* kSdof = R"(solid:
  model: sdof
  mass: 1.0
  damping: 2.5
  stiffness: 10.0
  force: [0.5, 0.0]
  interface_measure: 1.0
  initial_displacement: [0.0, 0.1]
  initial_velocity: 0.0
)";

std::string fem(const std::string& extra, const std::string& elements = "[4, 1]") {
  return "solid:\n  model: fem\n  mesh: {type: rectangle, origin: [0, 0], size: [1.0, 0.2], elements: " + elements +
         "}\n  material: {law: neo_hookean, youngs_modulus: 1.0e4, poisson_ratio: 0.3}\n  density: 10.0\n"
         "  clamp: left\n  interface: [top, right, bottom]\n" +
         extra;
}

const char* kSurrogate = R"(fluid:
  model: surrogate
  force: [1.282, 0.0]
  added_mass: 0.5
  interface_measure: 1.0
)";

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: fuzz_make_seeds CORPUS_DIR\n");
    return 1;
  }
  fsi_fuzz::quiet_logs();
  const std::filesystem::path root(argv[1]);
  const auto solid = root / "fuzz_solid_request";
  const auto fluid = root / "fuzz_fluid_request";
  write(solid, "seed_sdof", solid_sequence(kSdof, 0.0));
  write(solid, "seed_sdof_damping", solid_sequence(kSdof, 10.0));
  write(solid, "seed_fem_newmark", solid_sequence(fem("  probes: [{name: tip, point: [1.0, 0.1]}]\n"), 0.0));
  write(solid, "seed_fem_bdf2_damping",
        solid_sequence(fem("  time_scheme: bdf2\n  linear_solver: umfpack\n  gravity: [0, -2]\n"), 5.0));
  write(solid, "seed_fem_static",
        solid_sequence(
            fem("  analysis: static\n  load_steps: 2\n  newton: {max_iterations: 8, residual_tolerance: 1.0e-8}\n"
                "  tractions: [{boundary: top, traction: [0, -1]}]\n  point_loads: [{point: [1, 0.2], force: [0, "
                "-0.1]}]\n",
                "[3, 2]"),
            0.0, false));
  write(solid, "seed_fem_svk",
        solid_sequence(
            "solid:\n  model: fem\n  mesh: {type: rectangle, origin: [0, 0], size: [0.35, 0.02], elements: [5, 1]}\n"
            "  material: {law: saint_venant_kirchhoff, shear_modulus: 5.0e5, poisson_ratio: 0.4}\n  density: 1000\n"
            "  time_scheme: bdf1\n  clamp: [left]\n  interface: [top, bottom, right]\n  output_every: 2\n",
            0.0));
  {  // out of order and invalid requests
    fsi::protocol::SolidService service(fsi::models::make_solid_model, "seed");
    Builder b{service, {}};
    auto r = base(0);
    r.mutable_solve_step()->add_interface_force(1);
    b.send(r);
    b.send(get_interface());
    auto v = hello();
    v.set_protocol_version(7);
    b.send(v);
    b.send(configure("solid: {model: sdof, mass: -1}", 0.01, 0));
    b.send(accept(1, 0.01));
    b.send(configure(kSdof, 0.01, 0));
    auto bad = base(0);
    bad.mutable_solve_step()->add_interface_force(std::nan(""));
    bad.mutable_solve_step()->add_interface_force(0);
    b.send(bad);
    b.send(load(1, 0.01, "not a state"));
    b.sent.push_back("\x08\x01\x10");  // does not parse
    write(solid, "seed_errors", b.sent);
  }
  write(fluid, "seed_surrogate", fluid_sequence(kSurrogate));
  write(fluid, "seed_surrogate_default", fluid_sequence("fluid: {model: surrogate, force: 2}\n"));
  {
    fsi::protocol::FluidService service(fsi::models::make_fluid_model, "seed");
    Builder b{service, {}};
    auto r = base(0);
    r.mutable_initial_loads()->add_interface_displacement(1);
    b.send(r);
    b.send(configure("fluid: {model: surrogate, added_mass: -1}", 0.01, 0));
    b.send(configure(kSurrogate, 0.01, 0, 10));
    auto bad = base(0);
    bad.mutable_solve_step()->add_interface_displacement(1);
    b.send(bad);
    b.send(load(1, 0.01, "garbage"));
    auto solidish = base(0);
    solidish.mutable_solve_step()->add_interface_force(1);
    b.send(solidish);
    write(fluid, "seed_errors", b.sent);
  }
  std::printf("seeds written under %s\n", root.string().c_str());
  return 0;
}
