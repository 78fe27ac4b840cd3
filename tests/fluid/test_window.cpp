// Waveform iterations with the Navier-Stokes fluid (fluid.substeps > 1,
// NavierStokesFluid::solve_window): a window of n substeps equals n successive solve_step +
// accept_step calls fed the same interpolated interface data (to round-off), a repeated call
// (the next coupling iteration) restarts from the window's start whatever the call before it
// was given, and the window's end is the state accept_step() accepts: the probes after a window
// equal those after its last substep. On a moving cylinder (tests/fluid/prescribed_motion.hpp's
// mesh), BDF2 (parabolic interpolation) and BDF1 (linear), fixed and incremental mesh motion;
// and in 3D (a box of 10-node tetrahedra whose bottom face moves).
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <tuple>
#include <vector>

#include "fsi/common/config.hpp"
#include "fsi/common/waveform.hpp"
#include "fsi/fluid/navier_stokes_fluid.hpp"
#include "fsi/fluid/tet_mesh.hpp"

namespace {

using fsi::fluid::NavierStokesFluid;

constexpr double kWindow = 0.02;  // the coupling window Dt

struct Case {
  std::string element = "p1p1";
  std::string scheme = "bdf2";
  bool incremental = false;
  bool reuse = false;       // reuse_factorisation (BiCGSTAB on old factors: equal to its tolerance only)
  bool step_start = false;  // interface.penalty_geometry: step_start
};

std::string scene_text(const Case& c) {
  return std::string(R"(
fluid:
  model: fem
  element: )") +
         c.element + R"(
  mesh: {geo: )" +
         FSI_FLUID_SOURCE_DIR + R"(/configs/meshes/dfg_cylinder.geo, size: 0.1, parameters: {hc: 0.025}}
  density: 1.0
  viscosity: 0.001
  scheme: )" +
         c.scheme +
         R"(
  nonlinear: {max_iterations: 2, tolerance: 1.0e-12}
  linear_solver: {reuse_factorisation: )" +
         (c.reuse ? "true" : "false") + R"(}
  inflow: [{group: inlet, max_velocity: 1.5, ramp_time: 0.05}]
  walls: [walls]
  outlet: [outlet]
  interface: {groups: [cylinder], penalty: 50.0, symmetry: -1, mesh_incremental: )" +
         (c.incremental ? "true" : "false") + ", penalty_geometry: " + (c.step_start ? "step_start" : "current") +
         R"(}
  forces: [{name: cyl, groups: [cylinder]}]
  pressure_probes: {p_front: [0.15, 0.2]}
)";
}

struct Model {
  explicit Model(const Case& c) : scene(fsi::Scene::parse(scene_text(c), "inline")) {
    fsi::FluidSetup setup;
    setup.dt = kWindow;
    setup.end_time = 1.0;
    model.configure(scene.section("fluid"), setup);
    nodes = static_cast<Eigen::Index>(model.interface().nodes());
  }
  fsi::Scene scene;
  NavierStokesFluid model;
  Eigen::Index nodes = 0;
};

// The cylinder's motion at time t (every interface node alike), scaled by `factor` (a
// coupling iteration's wrong guess: factor != 1).
void motion(Eigen::Index nodes, double t, double factor, Eigen::VectorXd& d, Eigen::VectorXd& v) {
  const double w = 2 * M_PI / 0.16, a = 0.004 * factor;
  d.resize(2 * nodes);
  v.resize(2 * nodes);
  for (Eigen::Index i = 0; i < nodes; ++i) {
    d(2 * i) = 0.3 * a * std::sin(0.5 * w * t);
    d(2 * i + 1) = a * std::sin(w * t);
    v(2 * i) = 0.3 * a * 0.5 * w * std::cos(0.5 * w * t);
    v(2 * i + 1) = a * w * std::cos(w * t);
  }
}

// The interface waveforms over window `n` as the coupler sends them: the window's start, then
// `samples` samples (a solid in that many substeps); the fluid interpolates between them.
void waveforms(Eigen::Index nodes, int n, int samples, double factor, fsi::Waveform& d, fsi::Waveform& v) {
  d = v = fsi::Waveform{};
  const double start = (n - 1) * kWindow;
  for (int j = 0; j <= samples; ++j) {
    const double t = j == 0 ? start : fsi::substep_time(start, kWindow, j, samples);
    Eigen::VectorXd dj, vj;
    motion(nodes, t, j == 0 ? 1.0 : factor, dj, vj);
    d.times.push_back(t), v.times.push_back(t);
    d.values.push_back(dj), v.values.push_back(vj);
  }
}

double max_difference(const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  EXPECT_EQ(a.size(), b.size());
  return a.size() == b.size() && a.size() > 0 ? (a - b).cwiseAbs().maxCoeff() : INFINITY;
}

class FluidWindow : public ::testing::TestWithParam<std::tuple<std::string, std::string, bool>> {};

TEST_P(FluidWindow, EqualsSuccessiveSubstepsAndRestartsFromTheWindowStart) {
  Case c;
  c.element = std::get<0>(GetParam());
  c.scheme = std::get<1>(GetParam());
  c.incremental = std::get<2>(GetParam());
  const int substeps = 4, samples = 2, windows = 3;
  Model a(c), b(c);
  ASSERT_TRUE(a.model.supports_substeps());
  const Eigen::Index m = 2 * a.nodes;
  std::map<std::string, double> probes_a, probes_b;
  for (int n = 1; n <= windows; ++n) {
    SCOPED_TRACE("window " + std::to_string(n));
    const fsi::StepInfo info{n * kWindow, kWindow, n, 1};
    fsi::Waveform d, v, wrong_d, wrong_v;
    waveforms(a.nodes, n, samples, 1.0, d, v);
    waveforms(a.nodes, n, samples, 1.3, wrong_d, wrong_v);
    // Coupling iteration 1 with a wrong guess, 2 and 3 with the right one: 2 restarts from the
    // window's start (not from 1's end), and 3 repeats 2.
    a.model.solve_window(info, wrong_d, wrong_v, substeps);
    const fsi::FluidLoads second = a.model.solve_window({n * kWindow, kWindow, n, 2}, d, v, substeps);
    const fsi::FluidLoads third = a.model.solve_window({n * kWindow, kWindow, n, 3}, d, v, substeps);
    ASSERT_EQ(second.traction_samples.size(), m * substeps);
    ASSERT_EQ(second.velocity_integral_samples.size(), m * substeps);
    const double scale = second.traction_samples.cwiseAbs().maxCoeff();
    ASSERT_GT(scale, 0);
    EXPECT_LE(max_difference(second.traction_samples, third.traction_samples), 1e-12 * scale);
    // The window's end is also the loads' own traction_force / velocity_integral.
    EXPECT_EQ(max_difference(second.traction_samples.tail(m), second.traction_force), 0.0);
    EXPECT_EQ(max_difference(second.velocity_integral_samples.tail(m), second.velocity_integral), 0.0);
    probes_a = a.model.accept_step({n * kWindow, kWindow, n, 3});

    // The same substeps one by one, with the data interpolated as the window does.
    d.degree = v.degree = c.scheme == "bdf1" ? 1 : 2;
    for (int j = 1; j <= substeps; ++j) {
      SCOPED_TRACE("substep " + std::to_string(j));
      const double t = fsi::substep_time((n - 1) * kWindow, kWindow, j, substeps);
      const fsi::StepInfo sub{t, kWindow / substeps, (n - 1) * substeps + j, 1};
      const fsi::FluidLoads one = b.model.solve_step(sub, d.at(t), v.at(t));
      EXPECT_LE(max_difference(one.traction_force, third.traction_samples.segment((j - 1) * m, m)), 1e-11 * scale);
      EXPECT_LE(max_difference(one.velocity_integral, third.velocity_integral_samples.segment((j - 1) * m, m)),
                1e-11 * third.velocity_integral_samples.cwiseAbs().maxCoeff());
      probes_b = b.model.accept_step(sub);
    }
  }
  // The accepted window ends agree: the probes after the last window and after its last substep.
  for (const char* name : {"cyl_drag", "cyl_lift", "p_front", "mesh_min_scaled_jacobian"}) {
    ASSERT_EQ(probes_a.count(name), 1u) << name;
    EXPECT_NEAR(probes_a.at(name), probes_b.at(name), 1e-10 * std::max(1.0, std::abs(probes_b.at(name)))) << name;
  }
  EXPECT_GT(std::abs(probes_a.at("cyl_drag")), 1e-4);  // the flow did move
  // The wrong first iterations were solved too: more factorisations than the one-by-one run.
  EXPECT_GT(probes_a.at("factorisations"), probes_b.at("factorisations"));
}

INSTANTIATE_TEST_SUITE_P(ElementsSchemesMeshMotion, FluidWindow,
                         ::testing::Values(std::make_tuple(std::string("p1p1"), std::string("bdf2"), false),
                                           std::make_tuple(std::string("p1p1"), std::string("bdf1"), true),
                                           std::make_tuple(std::string("p2p1"), std::string("bdf2"), true)),
                         [](const auto& info) {
                           return std::get<0>(info.param) + "_" + std::get<1>(info.param) +
                                  (std::get<2>(info.param) ? "_incremental" : "_fixed_operator");
                         });

// With the factors reused (BiCGSTAB preconditioned by older factors, the default) the window's
// substeps see other factors than the one-by-one run: equal to the Krylov tolerance.
TEST(FluidWindow, WithReusedFactorsEqualsSuccessiveSubstepsToTheKrylovTolerance) {
  Case c;
  c.reuse = true;
  c.incremental = true;
  Model a(c), b(c);
  const int substeps = 2;
  const Eigen::Index m = 2 * a.nodes;
  for (int n = 1; n <= 3; ++n) {
    fsi::Waveform d, v, wrong_d, wrong_v;
    waveforms(a.nodes, n, 1, 1.0, d, v);
    waveforms(a.nodes, n, 1, 0.7, wrong_d, wrong_v);
    a.model.solve_window({n * kWindow, kWindow, n, 1}, wrong_d, wrong_v, substeps);
    const auto loads = a.model.solve_window({n * kWindow, kWindow, n, 2}, d, v, substeps);
    a.model.accept_step({n * kWindow, kWindow, n, 2});
    const double scale = loads.traction_samples.cwiseAbs().maxCoeff();
    for (int j = 1; j <= substeps; ++j) {
      const double t = fsi::substep_time((n - 1) * kWindow, kWindow, j, substeps);
      const fsi::StepInfo sub{t, kWindow / substeps, (n - 1) * substeps + j, 1};
      const auto one = b.model.solve_step(sub, d.at(t), v.at(t));
      EXPECT_LE(max_difference(one.traction_force, loads.traction_samples.segment((j - 1) * m, m)), 1e-7 * scale)
          << "window " << n << " substep " << j;
      b.model.accept_step(sub);
    }
  }
}

// The unit box as a gmsh MSH 2.2 file: 4-node tetrahedra (physical "fluid") and its six faces.
std::string box_msh(int n) {
  const auto mesh = fsi::fluid::TetMesh::box({0, 0, 0}, {1, 1, 1}, n, n, n);
  std::ostringstream out;
  out << "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$PhysicalNames\n7\n";
  int tag = 1;
  std::map<std::string, int> tags;
  for (const auto& [name, faces] : mesh.boundaries) {
    tags[name] = tag;
    out << "2 " << tag++ << " \"" << name << "\"\n";
  }
  out << "3 " << tag << " \"fluid\"\n$EndPhysicalNames\n$Nodes\n" << mesh.node_count() << "\n";
  out.precision(17);
  for (int i = 0; i < mesh.node_count(); ++i)
    out << i + 1 << " " << mesh.nodes(i, 0) << " " << mesh.nodes(i, 1) << " " << mesh.nodes(i, 2) << "\n";
  int faces = 0;
  for (const auto& [name, f] : mesh.boundaries) faces += static_cast<int>(f.rows());
  out << "$EndNodes\n$Elements\n" << faces + mesh.cell_count() << "\n";
  int id = 1;
  for (const auto& [name, f] : mesh.boundaries)
    for (int k = 0; k < f.rows(); ++k)
      out << id++ << " 2 2 " << tags[name] << " " << tags[name] << " " << f(k, 0) + 1 << " " << f(k, 1) + 1 << " "
          << f(k, 2) + 1 << "\n";
  for (int e = 0; e < mesh.cell_count(); ++e)
    out << id++ << " 4 2 " << tag << " " << tag << " " << mesh.tets(e, 0) + 1 << " " << mesh.tets(e, 1) + 1 << " "
        << mesh.tets(e, 2) + 1 << " " << mesh.tets(e, 3) + 1 << "\n";
  out << "$EndElements\n";
  return out.str();
}

// 3D (FlowSolver3, MeshMotion3): the box's bottom face moves up and down; a window of 3
// substeps equals the 3 substeps one by one, after a first call with a wrong guess.
TEST(FluidWindow, ThreeDimensionsEqualsSuccessiveSubsteps) {
  const auto dir = std::filesystem::temp_directory_path() / ("fsi_window3_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  std::ofstream(dir / "box.msh") << box_msh(2);
  const std::string text = R"(
fluid:
  model: fem
  dimension: 3
  element: p2p1
  mesh: {file: )" + (dir / "box.msh").string() +
                           R"(}
  density: 1.0
  viscosity: 0.1
  scheme: bdf2
  linear_solver: {engine: umfpack, reuse_factorisation: false}
  inflow: [{group: left, max_velocity: 1.0, direction: [1.0, 0.0, 0.0], ramp_time: 0.1}]
  walls: [top, back, front]
  outlet: [right]
  interface: {groups: [bottom], penalty: 50.0, symmetry: -1, mesh_incremental: true}
  forces: [{name: wall, groups: [bottom]}]
)";
  auto scene_a = fsi::Scene::parse(text, "inline"), scene_b = fsi::Scene::parse(text, "inline");
  fsi::FluidSetup setup;
  setup.dt = 0.05;
  setup.end_time = 1.0;
  NavierStokesFluid a, b;
  a.configure(scene_a.section("fluid"), setup);
  b.configure(scene_b.section("fluid"), setup);
  ASSERT_TRUE(a.supports_substeps());
  const auto iface = a.interface();
  ASSERT_EQ(iface.dimension, 3);
  const Eigen::Index nodes = static_cast<Eigen::Index>(iface.nodes()), m = 3 * nodes;
  // The bottom moves up by 0.02 sin(10 t) x (bump across the face), its velocity the derivative.
  const auto state = [&](double t, double factor, Eigen::VectorXd& d, Eigen::VectorXd& v) {
    d = v = Eigen::VectorXd::Zero(m);
    for (Eigen::Index i = 0; i < nodes; ++i) {
      const double x = iface.coordinates(i, 0), y = iface.coordinates(i, 1);
      const double bump = 16 * x * (1 - x) * y * (1 - y) * factor;
      d(3 * i + 2) = 0.02 * std::sin(10 * t) * bump;
      v(3 * i + 2) = 0.2 * std::cos(10 * t) * bump;
    }
  };
  const double dt = setup.dt;
  const int substeps = 3;
  std::map<std::string, double> pa, pb;
  for (int n = 1; n <= 2; ++n) {
    fsi::Waveform d, v, wd, wv;
    for (int j = 0; j <= 1; ++j) {  // a solid of one step: the window's start and end
      const double t = (n - 1 + j) * dt;
      Eigen::VectorXd dj, vj;
      state(t, 1.0, dj, vj);
      d.times.push_back(t), v.times.push_back(t), d.values.push_back(dj), v.values.push_back(vj);
      state(t, j == 0 ? 1.0 : 1.4, dj, vj);
      wd.times.push_back(t), wv.times.push_back(t), wd.values.push_back(dj), wv.values.push_back(vj);
    }
    a.solve_window({n * dt, dt, n, 1}, wd, wv, substeps);
    const auto loads = a.solve_window({n * dt, dt, n, 2}, d, v, substeps);
    ASSERT_EQ(loads.traction_samples.size(), m * substeps);
    pa = a.accept_step({n * dt, dt, n, 2});
    const double scale = loads.traction_samples.cwiseAbs().maxCoeff();
    ASSERT_GT(scale, 0);
    for (int j = 1; j <= substeps; ++j) {
      const double t = fsi::substep_time((n - 1) * dt, dt, j, substeps);
      const fsi::StepInfo sub{t, dt / substeps, (n - 1) * substeps + j, 1};
      const auto one = b.solve_step(sub, d.at(t), v.at(t));
      EXPECT_LE(max_difference(one.traction_force, loads.traction_samples.segment((j - 1) * m, m)), 1e-11 * scale)
          << "window " << n << " substep " << j;
      pb = b.accept_step(sub);
    }
  }
  for (const char* name : {"wall_drag", "wall_lift", "wall_side", "mesh_min_scaled_jacobian"})
    EXPECT_NEAR(pa.at(name), pb.at(name), 1e-10 * std::max(1.0, std::abs(pb.at(name)))) << name;
  std::filesystem::remove_all(dir);
}

// penalty_geometry step_start: the penalty term's interface (and the interface mass M_f sent to
// the coupler, the solid's damping M_G of the next iteration) is the window's start for every
// substep, not each substep's start: the same M_f as after the window start's accept.
TEST(FluidWindow, StepStartPenaltyIsTheWindowStartForEverySubstep) {
  Case c;
  c.step_start = true;
  c.incremental = true;
  Model a(c), b(Case{});
  const int substeps = 3;
  const auto iface = a.model.interface();
  // The cylinder breathes (its radius changes, so does its interface mass; a translation would not).
  const auto breathing = [&](int n, fsi::Waveform& d, fsi::Waveform& v) {
    d = v = fsi::Waveform{};
    for (int j = 0; j <= 1; ++j) {
      const double t = (n - 1 + j) * kWindow, w = 2 * M_PI / 0.16;
      Eigen::VectorXd dj(2 * a.nodes), vj(2 * a.nodes);
      for (Eigen::Index i = 0; i < a.nodes; ++i)
        for (int k = 0; k < 2; ++k) {
          const double r = iface.coordinates(i, k) - 0.2;  // from the centre (0.2, 0.2)
          dj(2 * i + k) = 0.1 * std::sin(w * t) * r;
          vj(2 * i + k) = 0.1 * w * std::cos(w * t) * r;
        }
      d.times.push_back(t), v.times.push_back(t), d.values.push_back(dj), v.values.push_back(vj);
    }
  };
  for (int n = 1; n <= 3; ++n) {
    SCOPED_TRACE("window " + std::to_string(n));
    const Eigen::SparseMatrix<double> start = a.model.solver().interface_mass();  // the accepted interface
    fsi::Waveform d, v;
    breathing(n, d, v);
    for (int k = 1; k <= 2; ++k) {
      const auto loads = a.model.solve_window({n * kWindow, kWindow, n, k}, d, v, substeps);
      ASSERT_EQ(loads.interface_mass.rows(), a.nodes);
      EXPECT_EQ((Eigen::MatrixXd(loads.interface_mass) - Eigen::MatrixXd(start)).cwiseAbs().maxCoeff(), 0.0);
    }
    a.model.accept_step({n * kWindow, kWindow, n, 2});
    // With penalty_geometry current the mass is the window end's (the last substep's interface).
    const auto current = b.model.solve_window({n * kWindow, kWindow, n, 1}, d, v, substeps);
    b.model.accept_step({n * kWindow, kWindow, n, 1});
    EXPECT_GT((Eigen::MatrixXd(current.interface_mass) - Eigen::MatrixXd(start)).cwiseAbs().maxCoeff(),
              1e-3 * Eigen::MatrixXd(start).cwiseAbs().maxCoeff());
  }
}

TEST(FluidWindow, SteadyFluidTakesNoSubsteps) {
  Case c;
  c.scheme = "steady";
  Model a(c);
  EXPECT_FALSE(a.model.supports_substeps());
  Model b(Case{});
  EXPECT_TRUE(b.model.supports_substeps());
}

}  // namespace
