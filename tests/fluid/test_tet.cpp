// The 3D fluid: the tetrahedral quadrature and P2 shape functions, the tetrahedral mesh from
// gmsh (and a 3D mesh refused by the 2D fluid), and the 3D FlowSolver (Taylor-Hood on
// tetrahedra) reproducing plane Poiseuille flow exactly (a quadratic velocity, a linear
// pressure: in the P2/P1 space) with Newton, also with a Nitsche interface (the coupling
// interface of the 3D fluid: its faces, its mass and its tractions).
#include <gtest/gtest.h>

#include <Eigen/LU>
#include <cmath>
#include <sstream>

#include "fsi/common/config.hpp"
#include "fsi/common/gmsh_reader.hpp"
#include "fsi/fluid/flow_solver.hpp"
#include "fsi/fluid/linear_solver.hpp"
#include "fsi/fluid/p2p1_tet_element.hpp"

namespace {

using namespace fsi::fluid;

double factorial(int n) { return n <= 1 ? 1.0 : n * factorial(n - 1); }

TEST(TetQuadrature, ExactForEveryMonomialUpToDegreeFive) {
  for (int a = 0; a <= 5; ++a)
    for (int b = 0; a + b <= 5; ++b)
      for (int c = 0; a + b + c <= 5; ++c) {
        double sum = 0;
        for (const auto& q : tet_quadrature()) sum += q.weight * std::pow(q.x, a) * std::pow(q.y, b) * std::pow(q.z, c);
        const double exact = factorial(a) * factorial(b) * factorial(c) / factorial(a + b + c + 3);
        EXPECT_NEAR(sum, exact, 1e-15) << a << " " << b << " " << c;
      }
}

TEST(P2TetElement, ShapeFunctionsAreNodalAndReproduceQuadratics) {
  const double pts[10][3] = {{0, 0, 0},     {1, 0, 0},   {0, 1, 0},   {0, 0, 1},     {0.5, 0, 0},
                             {0.5, 0.5, 0}, {0, 0.5, 0}, {0, 0, 0.5}, {0, 0.5, 0.5}, {0.5, 0, 0.5}};
  Eigen::Matrix<double, 10, 1> N;
  Eigen::Matrix<double, 10, 3> dN;
  for (int k = 0; k < 10; ++k) {
    p2_tet_shape(pts[k][0], pts[k][1], pts[k][2], N, dN);
    for (int j = 0; j < 10; ++j) EXPECT_NEAR(N(j), j == k ? 1.0 : 0.0, 1e-15) << k << " " << j;
  }
  // f = 1 + x - 2 y z + 3 x^2 interpolated at the nodes is f everywhere, with its gradient.
  auto f = [](double x, double y, double z) { return 1 + x - 2 * y * z + 3 * x * x; };
  Eigen::Matrix<double, 10, 1> values;
  for (int k = 0; k < 10; ++k) values(k) = f(pts[k][0], pts[k][1], pts[k][2]);
  const double x = 0.21, y = 0.17, z = 0.33;
  p2_tet_shape(x, y, z, N, dN);
  EXPECT_NEAR(N.dot(values), f(x, y, z), 1e-14);
  EXPECT_NEAR(dN.col(0).dot(values), 1 + 6 * x, 1e-13);
  EXPECT_NEAR(dN.col(1).dot(values), -2 * z, 1e-13);
  EXPECT_NEAR(dN.col(2).dot(values), -2 * y, 1e-13);
}

// One tetrahedron given clockwise (negative volume) with one boundary face, MSH 2.2.
const char* kOneTet = R"($MeshFormat
2.2 0 8
$EndMeshFormat
$PhysicalNames
2
2 2 "wall"
3 1 "fluid"
$EndPhysicalNames
$Nodes
4
1 0 0 0
2 0 1 0
3 1 0 0
4 0 0 1
$EndNodes
$Elements
2
1 2 2 2 2 1 2 3
2 4 2 1 1 1 2 3 4
$EndElements
)";

TEST(TetMesh, FromGmshOrientsTetrahedraAndTheTwoDimensionsRefuseEachOther) {
  std::istringstream in(kOneTet);
  const auto g = fsi::read_gmsh(in, "one_tet.msh");
  ASSERT_TRUE(g.has_volume());
  const auto m = TetMesh::from_gmsh(g);
  ASSERT_EQ(m.cell_count(), 1);
  Eigen::Matrix3d J;
  for (int k = 0; k < 3; ++k) J.col(k) = (m.nodes.row(m.tets(0, k + 1)) - m.nodes.row(m.tets(0, 0))).transpose();
  EXPECT_NEAR(J.determinant(), 1.0, 1e-15);  // flipped to positive volume
  EXPECT_EQ(m.boundary_nodes({"wall"}).size(), 3u);
  try {
    (void)FluidMesh::from_gmsh(g);
    FAIL() << "a 2D fluid took a 3D mesh";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("3D mesh"), std::string::npos) << e.what();
  }
  // A 2D mesh (triangles only) for the 3D fluid.
  std::istringstream in2(
      "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n3\n1 0 0 0\n2 1 0 0\n3 0 1 0\n$EndNodes\n"
      "$Elements\n1\n1 2 2 1 1 1 2 3\n$EndElements\n");
  EXPECT_THROW((void)TetMesh::from_gmsh(fsi::read_gmsh(in2, "tri.msh")), std::runtime_error);
}

// Steady Newton to 1e-12 without SUPG or factor reuse: the settings of every exact-solution case here.
FlowParameters steady_newton(double viscosity) {
  FlowParameters params;
  params.viscosity = viscosity;
  params.scheme = TimeScheme::Steady;
  params.newton = true;
  params.max_iterations = 8;
  params.tolerance = 1e-12;
  params.stabilisation.supg = false;
  params.reuse_factorisation = false;
  return params;
}

// Plane Poiseuille flow between y = 0 and y = H in a box with symmetry planes z = const:
// u = 4 U y (H - y) / H^2, p = 8 mu U (L - x) / H^2 (do-nothing outlet at x = L: p = 0).
TEST(FlowSolver3, PlanePoiseuilleIsExactWithNewton) {
  const double L = 2, H = 1, U = 1.5, mu = 0.1;
  TetMesh mesh = TetMesh::box({0, 0, 0}, {L, H, 0.5}, 4, 2, 1);
  FlowParameters params = steady_newton(mu);
  FlowSolver3 solver(mesh, params, "p2p1");
  EXPECT_EQ(solver.dofs(), 3 * solver.mesh().node_count() + solver.mesh().vertices());
  auto exact = [&](const Eigen::Vector3d& x, double) -> Eigen::Vector3d {
    return {4 * U * x.y() * (H - x.y()) / (H * H), 0, 0};
  };
  solver.add_dirichlet("left", exact);
  solver.add_dirichlet("bottom", exact);
  solver.add_dirichlet("top", exact);
  solver.add_symmetry("back");
  solver.add_symmetry("front");
  const auto report = solver.solve(1, 1, solver.mesh().nodes, {});
  EXPECT_LT(report.change, 1e-12);
  const auto v = solver.velocity();
  double err = 0;
  for (int i = 0; i < solver.mesh().node_count(); ++i)
    err = std::max(err, (v.row(i).transpose() - exact(solver.mesh().nodes.row(i).transpose(), 0)).norm());
  EXPECT_LT(err, 1e-10);
  for (const Eigen::Vector3d& x : {Eigen::Vector3d(0.3, 0.4, 0.2), Eigen::Vector3d(1.7, 0.9, 0.45)}) {
    EXPECT_NEAR(solver.pressure_at(x), 8 * mu * U * (L - x.x()) / (H * H), 1e-9);
    EXPECT_NEAR(solver.velocity_at(x).x(), 4 * U * x.y() * (H - x.y()) / (H * H), 1e-10);
  }
  // Forces by the residual (reaction) form. A single wall cannot be compared with its shear
  // alone: the nodes it shares with the inlet also carry their part of the inlet pressure (the
  // reaction at a node is the traction integrated against its shape function over every face it
  // touches). The union of the inlet and both walls is a closed balance: the inlet pushes with
  // p(0) H W = 8 mu U L / H^2 * H * W in +x, the walls hold with 2 * (4 mu U / H) L W in -x, and
  // these cancel (the outlet carries no x traction, the symmetry planes none either). The
  // balance holds to round-off only if every reaction is assembled consistently.
  const double W = 0.5;
  const Eigen::Vector3d f = solver.force({"left", "bottom", "top"});
  EXPECT_NEAR(f.x(), 0, 1e-9);
  EXPECT_NEAR(f.z(), 0, 1e-9);
  // The walls and the inlet separately are far from zero: the sum is not trivially small.
  EXPECT_GT(std::abs(solver.force({"bottom"}).x()), 0.5 * 4 * mu * U / H * L * W);
}

// The plane Poiseuille problem above on the given engine: the largest nodal velocity error.
struct PoiseuilleRun {
  double velocity_error = 0, pressure_error = 0;
  int krylov_iterations = 0;
  Eigen::VectorXd solution;
};
PoiseuilleRun poiseuille(LinearEngine engine, const std::string& petsc_options = "") {
  const double L = 2, H = 1, U = 1.5, mu = 0.1;
  FlowParameters params = steady_newton(mu);
  params.engine = engine;
  params.petsc_options = petsc_options;
  FlowSolver3 solver(TetMesh::box({0, 0, 0}, {L, H, 0.5}, 4, 2, 1), params, "p2p1");
  auto exact = [&](const Eigen::Vector3d& x, double) -> Eigen::Vector3d {
    return {4 * U * x.y() * (H - x.y()) / (H * H), 0, 0};
  };
  for (const char* g : {"left", "bottom", "top"}) solver.add_dirichlet(g, exact);
  solver.add_symmetry("back");
  solver.add_symmetry("front");
  const auto report = solver.solve(1, 1, solver.mesh().nodes, {});
  PoiseuilleRun run;
  run.krylov_iterations = report.krylov_iterations;
  const auto v = solver.velocity();
  for (int i = 0; i < solver.mesh().node_count(); ++i)
    run.velocity_error =
        std::max(run.velocity_error, (v.row(i).transpose() - exact(solver.mesh().nodes.row(i).transpose(), 0)).norm());
  const Eigen::Vector3d x(1.7, 0.9, 0.45);
  run.pressure_error = std::abs(solver.pressure_at(x) - 8 * mu * U * (L - x.x()) / (H * H));
  run.solution = solver.solution();
  return run;
}

TEST(FlowSolver3, PetscEnginesSolvePoiseuilleAsUmfpack) {
  if (!petsc_available()) GTEST_SKIP() << "built without PETSc";
  const auto lu = poiseuille(LinearEngine::Umfpack);
  EXPECT_LT(lu.velocity_error, 1e-10);
  // The field-split GMRES (default preconditioner) converges; with a tight tolerance its
  // solution is the LU one.
  const auto iterative = poiseuille(LinearEngine::Petsc, "-ksp_rtol 1e-13");
  EXPECT_GT(iterative.krylov_iterations, 0);
  EXPECT_LT(iterative.velocity_error, 1e-10);
  EXPECT_LT(iterative.pressure_error, 1e-9);
  EXPECT_LT((iterative.solution - lu.solution).lpNorm<Eigen::Infinity>(), 1e-9);
  const auto mumps = poiseuille(LinearEngine::Mumps);
  EXPECT_LT(mumps.velocity_error, 1e-10);
  EXPECT_LT((mumps.solution - lu.solution).lpNorm<Eigen::Infinity>(), 1e-10);
}

TEST(FlowSolver3, PetscRefusesAnUnknownOptionNamingIt) {
  if (!petsc_available()) GTEST_SKIP() << "built without PETSc";
  try {
    (void)poiseuille(LinearEngine::Petsc, "-ksp_rtol 1e-12 -ksp_no_such_option 3");
    FAIL() << "an unknown PETSc option was accepted";
  } catch (const fsi::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("-ksp_no_such_option"), std::string::npos) << e.what();
    EXPECT_EQ(std::string(e.what()).find("ksp_rtol"), std::string::npos) << e.what();
  }
  // An option with a value PETSc does not know fails with PETSc's message naming the value.
  try {
    (void)poiseuille(LinearEngine::Petsc, "-ksp_type no_such_krylov");
    FAIL() << "an unknown KSP type was accepted";
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find("no_such_krylov"), std::string::npos) << e.what();
  }
}

// A box whose whole boundary is the Nitsche interface, moving with a uniform velocity V: the
// flow u = V, p = 0 solves Navier-Stokes and the Nitsche conditions exactly; the interface is
// the box's faces (6-node triangles), its mass sums to the box's area and the traction is 0.
TEST(FlowSolver3Nitsche, TranslationOfTheWholeBoxIsExact) {
  const Eigen::Vector3d V(0.3, -0.2, 0.5);
  TetMesh mesh = TetMesh::box({0, 0, 0}, {1, 0.8, 0.6}, 2, 2, 2);
  FlowParameters params = steady_newton(0.05);
  params.nitsche_penalty = 100;
  FlowSolver3 solver(mesh, params, "p2p1");
  solver.set_interface({"left", "right", "bottom", "top", "back", "front"});
  solver.set_pressure_reference({0.5, 0.4, 0.3}, [](double) { return 0.0; });
  // 2 x 2 x 2 cells: 8 triangles on each of the six sides.
  ASSERT_EQ(solver.interface_faces().size(), 48u);
  EXPECT_EQ(solver.interface_nodes().size(), static_cast<std::size_t>(5 * 5 * 5 - 3 * 3 * 3));
  const auto n = static_cast<Eigen::Index>(solver.interface_nodes().size());
  Eigen::VectorXd vs(3 * n);
  for (Eigen::Index i = 0; i < n; ++i) vs.segment<3>(3 * i) = V;
  const auto report = solver.solve(1, 1, solver.mesh().nodes, vs);
  EXPECT_LT(report.change, 1e-12);
  const auto v = solver.velocity();
  double err = 0;
  for (int i = 0; i < solver.mesh().node_count(); ++i) err = std::max(err, (v.row(i).transpose() - V).norm());
  EXPECT_LT(err, 1e-11);
  EXPECT_NEAR(solver.pressure_at({0.2, 0.7, 0.1}), 0, 1e-10);
  EXPECT_NEAR(solver.interface_mass().sum(), 2 * (0.8 + 0.48 + 0.6), 1e-12);
  EXPECT_LT(solver.interface_traction().cwiseAbs().maxCoeff(), 1e-10);
}

// Plane Poiseuille flow as above with the bottom wall a Nitsche interface at rest (v_s = 0):
// still exact, and the traction on the interface is the wall shear tau = 4 mu U / H against
// the flow, node by node -tau times the node's row sum of the interface mass (away from the
// inlet, whose strongly held nodes carry the inlet pressure too; in z away from the symmetry
// planes, whose nodes carry their reaction).
TEST(FlowSolver3Nitsche, PoiseuilleWithNitscheInletAndWallsIsExactAndItsTractionIsTheShear) {
  const double L = 2, H = 1, U = 1.5, mu = 0.1, W = 0.5;
  TetMesh mesh = TetMesh::box({0, 0, 0}, {L, H, W}, 4, 2, 1);
  FlowParameters params = steady_newton(mu);
  params.nitsche_penalty = 50;
  FlowSolver3 solver(mesh, params, "p2p1");
  auto exact = [&](const Eigen::Vector3d& x, double) -> Eigen::Vector3d {
    return {4 * U * x.y() * (H - x.y()) / (H * H), 0, 0};
  };
  solver.add_dirichlet("left", exact);
  solver.add_dirichlet("top", exact);
  solver.add_symmetry("back");
  solver.add_symmetry("front");
  solver.set_interface({"bottom"});
  ASSERT_EQ(solver.interface_faces().size(), 8u);
  const auto report = solver.solve(1, 1, solver.mesh().nodes, {});
  EXPECT_LT(report.change, 1e-12);
  const auto v = solver.velocity();
  double err = 0;
  for (int i = 0; i < solver.mesh().node_count(); ++i)
    err = std::max(err, (v.row(i).transpose() - exact(solver.mesh().nodes.row(i).transpose(), 0)).norm());
  EXPECT_LT(err, 1e-10);
  EXPECT_NEAR(solver.pressure_at({0.3, 0.4, 0.2}), 8 * mu * U * (L - 0.3) / (H * H), 1e-9);
  const double tau = 4 * mu * U / H;
  const Eigen::SparseMatrix<double> M = solver.interface_mass();
  const Eigen::VectorXd row_sums = M * Eigen::VectorXd::Ones(M.cols());
  EXPECT_NEAR(row_sums.sum(), L * W, 1e-12);
  const Eigen::VectorXd f = solver.interface_traction();
  const auto& nodes = solver.interface_nodes();
  int checked = 0;
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    if (solver.mesh().nodes(nodes[i], 0) < 1e-12) continue;  // on the inlet
    const auto k = static_cast<Eigen::Index>(i);
    EXPECT_NEAR(f(3 * k), -tau * row_sums(k), 1e-9) << "node " << nodes[i];
    const double z = solver.mesh().nodes(nodes[i], 2);
    if (z > 1e-12 && z < W - 1e-12) {
      EXPECT_NEAR(f(3 * k + 2), 0, 1e-9);  // (the symmetry planes' reactions)
    }
    ++checked;
  }
  EXPECT_EQ(checked, 9 * 3 - 3);
}

// Pressure-driven plane Poiseuille flow: the inlet x = 0 a prescribed normal traction -p_in n,
// the outlet do-nothing (p = 0), no-slip walls y = 0, H: u = p_in y (H - y) / (2 mu L),
// p = p_in (1 - x / L), exactly in the P2/P1 space. The pressure reaches the flow only
// through the traction: doubling p_in doubles the flow.
TEST(FlowSolver3, PressureInletDrivesExactPoiseuille) {
  const double L = 2, H = 1, mu = 0.1, p_in = 0.6;
  TetMesh mesh = TetMesh::box({0, 0, 0}, {L, H, 0.5}, 4, 2, 1);
  FlowParameters params = steady_newton(mu);
  FlowSolver3 solver(mesh, params, "p2p1");
  const auto zero = [](const Eigen::Vector3d&, double) { return Eigen::Vector3d::Zero().eval(); };
  solver.add_dirichlet("bottom", zero);
  solver.add_dirichlet("top", zero);
  solver.add_symmetry("back");
  solver.add_symmetry("front");
  solver.add_pressure("left", [&](double) { return p_in; });
  const auto report = solver.solve(1, 1, solver.mesh().nodes, {});
  EXPECT_LT(report.change, 1e-12);
  const auto v = solver.velocity();
  double err = 0;
  for (int i = 0; i < solver.mesh().node_count(); ++i) {
    const double y = solver.mesh().nodes(i, 1);
    err = std::max(err, (v.row(i).transpose() - Eigen::Vector3d(p_in * y * (H - y) / (2 * mu * L), 0, 0)).norm());
  }
  EXPECT_LT(err, 1e-10);
  EXPECT_NEAR(solver.pressure_at({0.3, 0.4, 0.2}), p_in * (1 - 0.3 / L), 1e-10);
}

}  // namespace
