// The 3D moving mesh: the GCL of the 3D FlowSolver on a box of 10-node tetrahedra (a uniform and
// a linear flow reproduced on a moving mesh, BDF1 and BDF2, with a wrong mesh velocity as the
// control that fails), MeshMotion3 (prescribed and fixed nodes, 10-node midpoints, a rigid
// translation, the first bump amplitude that inverts an element for each method, checkpoints),
// TetMeshQuality, and the 3D VTK file read back with meshio (read_vtu.py).
#include <gtest/gtest.h>
#include <unistd.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include "fsi/common/config.hpp"
#include "fsi/common/solver_model.hpp"
#include "fsi/common/state.hpp"
#include "fsi/fluid/flow_solver.hpp"
#include "fsi/fluid/flow_vtk.hpp"
#include "fsi/fluid/mesh_motion.hpp"
#include "fsi/fluid/mesh_quality.hpp"
#include "fsi/fluid/navier_stokes_fluid.hpp"

namespace {

using namespace fsi::fluid;

// ---------------------------------------------------------------------------------------------
// GCL: a uniform flow u = U and a linear (Couette-like) flow u = (0.2 + y + 0.5 z, 0, 0), p = 0,
// solve Navier-Stokes exactly and lie in the P2 space; on a moving mesh their nodal values must
// stay exact to round-off. The uniform flow checks the BDF time derivative and the moving
// geometry (its convective term vanishes whatever the mesh velocity); the linear flow's nodal
// values change as the nodes move, which only the right mesh velocity -(w . grad) u cancels.

enum class Motion { Translation, Shear };

Eigen::MatrixX3d moved(const TetMesh& mesh, Motion motion, double t) {
  Eigen::MatrixX3d x = mesh.nodes;
  for (int i = 0; i < mesh.node_count(); ++i) {
    const Eigen::RowVector3d p = mesh.nodes.row(i);
    if (motion == Motion::Translation) {
      x.row(i) += std::sin(3 * t) * Eigen::RowVector3d(0.1, 0.06, -0.04);
    } else {  // a time-dependent shear of the whole box (linear in x: straight edges stay straight)
      x(i, 0) += 0.15 * std::sin(4 * t) * p.y() + 0.05 * std::sin(2 * t) * p.z();
      x(i, 2) += 0.1 * std::sin(3 * t) * p.x();
    }
  }
  return x;
}

struct GclResult {
  double error = 0;   // max |u - exact| over the nodes and steps, max |p|
  double motion = 0;  // max nodal displacement
};

GclResult gcl(TimeScheme scheme, Motion motion, bool linear_flow, double mesh_velocity_scale = 1.0) {
  FlowParameters p;
  p.viscosity = 0.01;
  p.scheme = scheme;
  p.stabilisation.supg = false;
  p.reuse_factorisation = false;  // direct solves: the check is to round-off
  p.mesh_velocity_scale = mesh_velocity_scale;
  FlowSolver3 s(TetMesh::box({0, 0, 0}, {1, 1, 1}, 3, 3, 3), p, "p2p1");
  const auto& mesh = s.mesh();
  const Eigen::Vector3d U(1.0, 0.5, -0.3);
  auto exact = [&](const Eigen::Vector3d& x, double) -> Eigen::Vector3d {
    return linear_flow ? Eigen::Vector3d(0.2 + x.y() + 0.5 * x.z(), 0, 0) : U;
  };
  // Every face Dirichlet (a do-nothing outlet would be wrong for the linear flow once the shear
  // tilts it: grad u . n != 0), the pressure pinned at a vertex.
  for (const char* g : {"left", "right", "bottom", "top", "back", "front"}) s.add_dirichlet(g, exact);
  s.set_pressure_reference(Eigen::Vector3d(0, 0, 0), [](double) { return 0.0; });
  Eigen::MatrixX3d initial(mesh.node_count(), 3);
  for (int i = 0; i < mesh.node_count(); ++i) initial.row(i) = exact(mesh.nodes.row(i).transpose(), 0).transpose();
  s.set_initial_velocity(initial);
  const double dt = 0.05;
  GclResult r;
  for (int n = 1; n <= 12; ++n) {
    const auto x = moved(mesh, motion, n * dt);
    s.solve(n * dt, dt, x, {});
    s.accept();
    const auto v = s.velocity();
    for (int i = 0; i < mesh.node_count(); ++i)
      r.error = std::max(r.error, (v.row(i).transpose() - exact(x.row(i).transpose(), 0)).norm());
    r.error = std::max(r.error, s.pressure().cwiseAbs().maxCoeff());
    r.motion = std::max(r.motion, (x - mesh.nodes).cwiseAbs().maxCoeff());
  }
  return r;
}

struct GclCase {
  TimeScheme scheme;
  Motion motion;
  bool linear_flow;
};

std::string name(const GclCase& c) {
  return std::string(c.scheme == TimeScheme::BDF1 ? "BDF1" : "BDF2") +
         (c.motion == Motion::Shear ? "Shear" : "Translation") + (c.linear_flow ? "LinearFlow" : "UniformFlow");
}
void PrintTo(const GclCase& c, std::ostream* os) { *os << name(c); }  // ctest names without padding bytes

class Gcl3 : public ::testing::TestWithParam<GclCase> {};

TEST_P(Gcl3, FlowIsReproducedToRoundOffOnTheMovingMesh) {
  const auto c = GetParam();
  const auto r = gcl(c.scheme, c.motion, c.linear_flow);
  std::printf("GCL 3D %s %s %s flow: max |u - exact| = %.2e (max motion %.3f)\n",
              c.scheme == TimeScheme::BDF1 ? "BDF1" : "BDF2", c.motion == Motion::Shear ? "shear" : "translation",
              c.linear_flow ? "linear" : "uniform", r.error, r.motion);
  EXPECT_GT(r.motion, 0.05);
  EXPECT_LT(r.error, 1e-12);
}

INSTANTIATE_TEST_SUITE_P(Cases, Gcl3,
                         ::testing::Values(GclCase{TimeScheme::BDF1, Motion::Translation, false},
                                           GclCase{TimeScheme::BDF2, Motion::Translation, false},
                                           GclCase{TimeScheme::BDF1, Motion::Shear, false},
                                           GclCase{TimeScheme::BDF2, Motion::Shear, false},
                                           GclCase{TimeScheme::BDF1, Motion::Shear, true},
                                           GclCase{TimeScheme::BDF2, Motion::Shear, true}),
                         [](const ::testing::TestParamInfo<GclCase>& info) { return name(info.param); });

TEST(Gcl3Control, AWrongMeshVelocityFails) {
  // The same checks with the mesh velocity off (scale 0) and half its value: the linear flow
  // on the shearing mesh is then far from exact, so the tests above can fail.
  for (const double scale : {0.0, 0.5}) {
    const auto r = gcl(TimeScheme::BDF2, Motion::Shear, true, scale);
    std::printf("GCL 3D control (mesh velocity x %.1f, BDF2 shear linear flow): max |u - exact| = %.2e\n", scale,
                r.error);
    EXPECT_GT(r.error, 1e-4);
  }
}

// ---------------------------------------------------------------------------------------------
// MeshMotion3

MeshMotionOptions options(MeshMotionOptions::Method method, bool incremental) {
  MeshMotionOptions o;
  o.method = method;
  o.incremental = incremental;
  o.stiffening = 1.0;
  return o;
}

const std::array<MeshMotionOptions::Method, 2> kMethods = {MeshMotionOptions::Method::Harmonic,
                                                           MeshMotionOptions::Method::Elastic};

bool is_midpoint_of(const TetMesh& m, int node, int* a, int* b) {
  for (int e = 0; e < m.cell_count(); ++e)
    for (int k = 0; k < 6; ++k)
      if (m.edge_nodes(e, k) == node) {
        *a = m.tets(e, kTetEdges[k][0]);
        *b = m.tets(e, kTetEdges[k][1]);
        return true;
      }
  return false;
}

TEST(MeshMotion3, PrescribedFollowFixedStayFreeMidpointsFollowTheirEdge) {
  const auto mesh = TetMesh::box({0, 0, 0}, {1, 1, 1}, 4, 4, 4).quadratic_from_linear();
  const auto moving = mesh.boundary_nodes({"bottom"});  // y = 0, with its midpoints
  const auto fixed = mesh.boundary_nodes({"top"});
  // A curved displacement: the interface midpoints must take theirs, not their edge's mean.
  Eigen::VectorXd d(3 * static_cast<Eigen::Index>(moving.size()));
  for (std::size_t k = 0; k < moving.size(); ++k) {
    const Eigen::RowVector3d x = mesh.nodes.row(moving[k]);
    d.segment<3>(3 * static_cast<Eigen::Index>(k)) << 0.05 * x.z(),
        0.1 * std::sin(M_PI * x.x()) * std::sin(M_PI * x.z()), 0.0;
  }
  for (auto method : kMethods) {
    MeshMotion3 motion(mesh, moving, fixed, options(method, true));
    const Eigen::MatrixX3d u = motion.extend(d);
    for (std::size_t k = 0; k < moving.size(); ++k)
      EXPECT_EQ((u.row(moving[k]).transpose() - d.segment<3>(3 * static_cast<Eigen::Index>(k))).norm(), 0.0);
    for (int i : fixed) EXPECT_EQ(u.row(i).norm(), 0.0);
    std::vector<char> prescribed(static_cast<std::size_t>(mesh.node_count()), 0);
    for (int i : moving) prescribed[static_cast<std::size_t>(i)] = 1;
    for (int i : fixed) prescribed[static_cast<std::size_t>(i)] = 1;
    int free_midpoints = 0;
    for (int i = mesh.vertices(); i < mesh.node_count(); ++i) {
      if (prescribed[static_cast<std::size_t>(i)]) continue;
      int a, b;
      ASSERT_TRUE(is_midpoint_of(mesh, i, &a, &b));
      EXPECT_LT((u.row(i) - 0.5 * (u.row(a) + u.row(b))).norm(), 1e-15);
      ++free_midpoints;
    }
    EXPECT_GT(free_midpoints, 100);
    EXPECT_LT((motion.positions(d) - (mesh.nodes + u)).cwiseAbs().maxCoeff(), 1e-15);
    // Incremental: accepting a state and extending it again reproduces it.
    motion.accept(d);
    EXPECT_LT((motion.extend(d) - u).cwiseAbs().maxCoeff(), 1e-14);
  }
}

TEST(MeshMotion3, RigidTranslationOfTheInterfaceMovesTheMeshRigidly) {
  // Nothing held: the extension of a rigid translation is the translation everywhere (harmonic:
  // constants are harmonic; elastic: a rigid motion is stress-free), and the quality is unchanged.
  for (const bool quadratic : {false, true}) {
    auto mesh = TetMesh::box({0, 0, 0}, {1, 0.5, 1}, 3, 2, 3);
    if (quadratic) mesh = mesh.quadratic_from_linear();
    const auto moving = mesh.boundary_nodes({"bottom"});
    const Eigen::RowVector3d t(0.3, -0.2, 0.7);
    const Eigen::VectorXd d = t.transpose().replicate(static_cast<Eigen::Index>(moving.size()), 1).reshaped();
    const auto reference = mesh_quality(mesh, mesh.nodes);
    for (auto method : kMethods) {
      MeshMotion3 motion(mesh, moving, {}, options(method, false));
      const Eigen::MatrixX3d x = motion.positions(d);
      EXPECT_LT((x - (mesh.nodes.rowwise() + t)).cwiseAbs().maxCoeff(), 1e-12);
      const auto q = mesh_quality(mesh, x);
      EXPECT_NEAR(q.min_volume_ratio, 1.0, 1e-12);
      EXPECT_NEAR(q.min_scaled_jacobian, reference.min_scaled_jacobian, 1e-12);
      EXPECT_NEAR(q.min_shape, reference.min_shape, 1e-12);
      EXPECT_NEAR(q.min_curved_jacobian, 1.0, 1e-12);
      EXPECT_EQ(q.inverted, 0);
    }
  }
}

// The bottom wall (y = 0) of the unit box bulges by amplitude * sin(pi x) sin(pi z) (the other
// walls held): the first amplitude (steps of 0.02 up to 0.8) at which an element inverts (or
// a 10-node element folds), one-shot or accepted step by step (incremental). 0: none up to 0.8.
double first_inverting_amplitude(bool quadratic, MeshMotionOptions::Method method, bool incremental) {
  auto mesh = TetMesh::box({0, 0, 0}, {1, 1, 1}, 6, 6, 6);
  if (quadratic) mesh = mesh.quadratic_from_linear();
  const auto moving = mesh.boundary_nodes({"bottom"});
  const auto fixed = mesh.boundary_nodes({"left", "right", "top", "back", "front"});
  MeshMotion3 motion(mesh, moving, fixed, options(method, incremental));
  for (int s = 1; s <= 40; ++s) {
    const double amplitude = 0.02 * s;
    Eigen::VectorXd d = Eigen::VectorXd::Zero(3 * static_cast<Eigen::Index>(moving.size()));
    for (std::size_t k = 0; k < moving.size(); ++k)
      d(3 * static_cast<Eigen::Index>(k) + 1) =
          amplitude * std::sin(M_PI * mesh.nodes(moving[k], 0)) * std::sin(M_PI * mesh.nodes(moving[k], 2));
    const auto q = mesh_quality(mesh, motion.positions(d));
    if (q.inverted > 0) return amplitude;
    motion.accept(d);
  }
  return 0;
}

TEST(MeshMotion3, ElasticAndIncrementalKeepABumpedWallValidLonger) {
  double found[2][2][2];
  for (int quadratic = 0; quadratic < 2; ++quadratic)
    for (int m = 0; m < 2; ++m)
      for (int inc = 0; inc < 2; ++inc) {
        found[quadratic][m][inc] = first_inverting_amplitude(quadratic, kMethods[static_cast<std::size_t>(m)], inc);
        std::printf("bump 6x6x6 %s-node %s %s: first inverting amplitude %.2f%s\n", quadratic ? "10" : "4",
                    m ? "elastic" : "harmonic", inc ? "incremental" : "one-shot", found[quadratic][m][inc],
                    found[quadratic][m][inc] == 0 ? " (none up to 0.8)" : "");
      }
  auto later = [](double a) { return a == 0 ? 1.0 : a; };  // 0: never inverted (up to 0.8)
  for (int quadratic = 0; quadratic < 2; ++quadratic) {
    EXPECT_GT(found[quadratic][0][0], 0.0) << "the one-shot harmonic extension should fold at some amplitude";
    EXPECT_GT(later(found[quadratic][1][0]), found[quadratic][0][0]) << "elastic beats harmonic";
    EXPECT_GE(later(found[quadratic][0][1]), found[quadratic][0][0]) << "incremental harmonic beats one-shot";
    EXPECT_GE(later(found[quadratic][1][1]), found[quadratic][1][0]) << "incremental elastic beats one-shot";
  }
}

TEST(MeshMotion3, AcceptingAnInvertedMeshNamesTheTetrahedronAndWhere) {
  const auto mesh = TetMesh::box({0, 0, 0}, {1, 1, 1}, 3, 3, 3);
  const auto moving = mesh.boundary_nodes({"bottom"});
  MeshMotion3 motion(mesh, moving, mesh.boundary_nodes({"top"}), options(kMethods[0], true));
  Eigen::VectorXd d = Eigen::VectorXd::Zero(3 * static_cast<Eigen::Index>(moving.size()));
  for (std::size_t k = 0; k < moving.size(); ++k) d(3 * static_cast<Eigen::Index>(k) + 1) = 1.5;  // through the top
  try {
    motion.accept(d);
    FAIL() << "expected a SolverError";
  } catch (const fsi::SolverError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("tetrahedron"), std::string::npos) << what;
    EXPECT_NE(what.find("near ("), std::string::npos) << what;
    EXPECT_NE(what.find("inverted"), std::string::npos) << what;
  }
}

TEST(MeshMotion3, CheckpointRestoresTheIncrementalStateBitForBit) {
  const auto mesh = TetMesh::box({0, 0, 0}, {1, 1, 1}, 3, 3, 3).quadratic_from_linear();
  const auto moving = mesh.boundary_nodes({"bottom"});
  const auto fixed = mesh.boundary_nodes({"top"});
  auto bump = [&](double a) {
    Eigen::VectorXd d = Eigen::VectorXd::Zero(3 * static_cast<Eigen::Index>(moving.size()));
    for (std::size_t k = 0; k < moving.size(); ++k)
      d(3 * static_cast<Eigen::Index>(k) + 1) = a * std::sin(M_PI * mesh.nodes(moving[k], 0));
    return d;
  };
  MeshMotion3 a(mesh, moving, fixed, options(kMethods[1], true));
  a.accept(bump(0.1));
  a.accept(bump(0.2));
  fsi::StateArchive state;
  a.save_state(state, "mesh.");
  MeshMotion3 b(mesh, moving, fixed, options(kMethods[1], true));
  b.load_state(state, "mesh.");
  const Eigen::MatrixX3d ua = a.extend(bump(0.3)), ub = b.extend(bump(0.3));
  EXPECT_EQ((ua - ub).cwiseAbs().maxCoeff(), 0.0);
  MeshMotion3 two_d_sized(TetMesh::box({0, 0, 0}, {1, 1, 1}, 2, 2, 2), {}, {}, options(kMethods[0], true));
  EXPECT_THROW(two_d_sized.load_state(state, "mesh."), fsi::StateError);
}

// ---------------------------------------------------------------------------------------------
// TetMeshQuality

TEST(TetMeshQuality, RegularIsOneInvertedIsCountedAndLocated) {
  TetMesh m;
  m.nodes.resize(4, 3);
  m.nodes << 1, 1, 1, 1, -1, -1, -1, 1, -1, -1, -1, 1;  // regular, edge 2 sqrt(2)
  m.tets.resize(1, 4);
  m.tets << 0, 1, 2, 3;
  if (mesh_quality(m, m.nodes).min_scaled_jacobian < 0) m.tets << 0, 2, 1, 3;  // positive volume
  auto q = mesh_quality(m, m.nodes);
  EXPECT_NEAR(q.min_scaled_jacobian, 1.0, 1e-14);
  EXPECT_NEAR(q.min_shape, 1.0, 1e-14);
  EXPECT_NEAR(q.min_volume_ratio, 1.0, 1e-14);
  EXPECT_EQ(q.inverted, 0);
  // Vertex 3 pushed through the opposite face: inverted, located at the moved centroid.
  Eigen::MatrixX3d x = m.nodes;
  x.row(3) << 1, 1, -3;
  q = mesh_quality(m, x);
  EXPECT_LT(q.min_scaled_jacobian, 0);
  EXPECT_LT(q.min_shape, 0);
  EXPECT_EQ(q.inverted, 1);
  EXPECT_EQ(q.worst_element, 0);
  EXPECT_LT((q.worst_centre - x.colwise().mean().transpose()).norm(), 1e-14);
  const auto text = q.describe();
  EXPECT_NE(text.find("tetrahedron 0 near (0.5, 0.5, -1)"), std::string::npos) << text;
  EXPECT_NE(text.find("1 inverted"), std::string::npos) << text;
  // A 10-node tetrahedron with straight edges: curved Jacobian 1; a midpoint pulled across: folds.
  const auto q10 = m.quadratic_from_linear();
  EXPECT_NEAR(mesh_quality(q10, q10.nodes).min_curved_jacobian, 1.0, 1e-12);
  Eigen::MatrixX3d x10 = q10.nodes;
  const int mid = q10.edge_nodes(0, 0);
  const int v0 = q10.tets(0, 0), v1 = q10.tets(0, 1);
  x10.row(mid) = x10.row(v0) + 0.9 * (x10.row(v1) - x10.row(v0));  // beyond 3/4 of the edge the map folds
  const auto qc = mesh_quality(q10, x10);
  EXPECT_LE(qc.min_curved_jacobian, 0);
  EXPECT_GT(qc.min_scaled_jacobian, 0.99);  // the straight tetrahedron is still fine
  EXPECT_EQ(qc.inverted, 1);
}

// ---------------------------------------------------------------------------------------------
// VTK in 3D: written by flow_vtk_grid / write_vtu, read back by meshio (read_vtu.py).

std::string run(const std::string& command) {
  std::string out;
  if (FILE* p = popen(command.c_str(), "r")) {
    char buf[4096];
    while (std::size_t n = fread(buf, 1, sizeof buf, p)) out.append(buf, n);
    if (pclose(p) != 0) return "FAILED: " + out;
  }
  return out;
}

TEST(Vtk3, QuadraticTetrahedraAreReadBackWithTheirValues) {
  if (run("/usr/bin/python3 -c 'import meshio' 2>&1").find("FAILED") != std::string::npos) GTEST_SKIP() << "no meshio";
  FlowParameters p;
  p.scheme = TimeScheme::BDF1;
  FlowSolver3 s(TetMesh::box({0, 0, 0}, {1, 0.5, 0.5}, 2, 2, 2), p, "p2p1");
  const auto& mesh = s.mesh();
  // A known velocity: u = (x, 2 y, -3 z).
  Eigen::MatrixX3d u(mesh.node_count(), 3);
  for (int i = 0; i < mesh.node_count(); ++i) u.row(i) << mesh.nodes(i, 0), 2 * mesh.nodes(i, 1), -3 * mesh.nodes(i, 2);
  s.set_initial_velocity(u);
  const auto dir = std::filesystem::temp_directory_path() / ("fsi_vtk3_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  for (const auto format : {fsi::VtkFormat::Binary, fsi::VtkFormat::Ascii}) {
    const auto file = dir / (std::string("fluid_") + fsi::to_string(format) + ".vtu");
    fsi::write_vtu(file, flow_vtk_grid(s), format);
    const std::string out = run("/usr/bin/python3 " FSI_FLUID_TEST_DIR "/read_vtu.py " + file.string());
    std::printf("%s", out.c_str());
    std::istringstream in(out);
    std::string key;
    int points = -1, cells = -1, midpoint_errors = -1, negative = -1, vtk_cells = -1, vtk_type = -1;
    double velocity_error = -1, pressure_size = -1;
    while (in >> key) {
      if (key == "points") in >> points;
      if (key == "tetra10") in >> cells;
      if (key == "velocity_error") in >> velocity_error;
      if (key == "pressure_points") in >> pressure_size;
      if (key == "midpoints_off_their_edge") in >> midpoint_errors;
      if (key == "negative_volumes") in >> negative;
      if (key == "vtk_cells") in >> vtk_cells;
      if (key == "vtk_cell_type") in >> vtk_type;
    }
    EXPECT_EQ(points, mesh.node_count()) << out;
    EXPECT_EQ(cells, mesh.cell_count()) << out;
    EXPECT_EQ(pressure_size, mesh.node_count()) << out;
    EXPECT_EQ(midpoint_errors, 0) << out;  // VTK's edge order (01 12 20 03 13 23)
    EXPECT_EQ(negative, 0) << out;
    if (vtk_cells >= 0) {  // VTK's reader (python3-vtk9) agrees: ParaView reads the file
      EXPECT_EQ(vtk_cells, mesh.cell_count()) << out;
      EXPECT_EQ(vtk_type, 24) << out;
    }
    EXPECT_GE(velocity_error, 0) << out;
    EXPECT_LT(velocity_error, format == fsi::VtkFormat::Binary ? 1e-15 : 1e-8) << out;
  }
  std::filesystem::remove_all(dir);
}

// The box as a gmsh MSH 2.2 file: 4-node tetrahedra (physical "fluid") and its six faces.
std::string box_msh(int n) {
  const auto mesh = TetMesh::box({0, 0, 0}, {1, 1, 1}, n, n, n);
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

TEST(Vtk3, TheSceneWritesEveryVtkEveryStepsIn3D) {
  if (run("/usr/bin/python3 -c 'import meshio' 2>&1").find("FAILED") != std::string::npos) GTEST_SKIP() << "no meshio";
  const auto dir = std::filesystem::temp_directory_path() / ("fsi_vtk3_scene_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const int n = 2;
  std::ofstream(dir / "box.msh") << box_msh(n);
  const std::string text = R"(
fluid:
  model: fem
  dimension: 3
  element: p2p1
  mesh: {file: )" + (dir / "box.msh").string() +
                           R"(}
  density: 1.0
  viscosity: 0.1
  scheme: bdf1
  inflow: [{group: left, max_velocity: 1.0, direction: [1.0, 0.0, 0.0]}]
  walls: [bottom, top, back, front]
  outlet: [right]
  output: {vtk_every: 2}
)";
  auto scene = fsi::Scene::parse(text, "inline");
  fsi::FluidSetup setup;
  setup.dt = 0.1;
  setup.end_time = 0.3;
  setup.output_dir = (dir / "out").string();
  std::filesystem::create_directories(setup.output_dir);
  NavierStokesFluid model;
  EXPECT_EQ(scene.section("fluid").get<std::string>("model"), "fem");  // the factory's key
  model.configure(scene.section("fluid"), setup);
  scene.check_all_used("fluid");  // fluid.output.vtk_every is read in 3D
  std::vector<std::string> written;
  for (int step = 1; step <= 3; ++step) {
    const fsi::StepInfo info{step * 0.1, 0.1, step, 1};
    model.solve_step(info, {}, {});
    model.accept_step(info);
    for (const auto& f : model.write_output(info)) written.push_back(f);
  }
  ASSERT_EQ(written.size(), 1u);  // step 2 only
  EXPECT_NE(written[0].find("fluid_000002.vtu"), std::string::npos) << written[0];
  const std::string out = run("/usr/bin/python3 -c \"import meshio; m = meshio.read('" + written[0] +
                              "'); print(len(m.points), sum(len(c.data) for c in m.cells if c.type == 'tetra10'), "
                              "m.point_data['velocity'][:, 0].max())\"");
  std::istringstream in(out);
  int points = 0, cells = 0;
  double umax = 0;
  in >> points >> cells >> umax;
  EXPECT_EQ(points, (2 * n + 1) * (2 * n + 1) * (2 * n + 1)) << out;
  EXPECT_EQ(cells, 6 * n * n * n) << out;
  EXPECT_NEAR(umax, 1.0, 0.5) << out;  // the inflow's speed, from the solution
  std::filesystem::remove_all(dir);
}

}  // namespace
