// The PETSc engines on however many MPI ranks this test runs on (ctest: 1 rank, and 2 ranks
// under mpirun: fluid.mpi_two_ranks): the 3D plane Poiseuille problem of test_tet.cpp solved by
// MUMPS and by the field-split GMRES equals the UMFPACK solution on rank 0. Ranks other than 0
// serve the PETSc solves (start_mpi_ranks), as in fluid_server. On 2 ranks the element matrices
// are computed by both (summed on rank 0, or partitioned: each rank keeps its cells and fills its
// rows): a moving-mesh Navier-Stokes step equals rank 0's assembly alone, and an inverted cell in
// either rank's block is reported.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

#include "fsi/fluid/flow_solver.hpp"
#include "fsi/fluid/linear_solver.hpp"

namespace {

using namespace fsi::fluid;
int expected_ranks = 0;  // --expect-ranks=N

Eigen::VectorXd poiseuille(LinearEngine engine, const std::string& options, int& iterations) {
  const double L = 2, H = 1, U = 1.5;
  FlowParameters params;
  params.viscosity = 0.1;
  params.scheme = TimeScheme::Steady;
  params.newton = true;
  params.max_iterations = 8;
  params.tolerance = 1e-12;
  params.stabilisation.supg = false;
  params.reuse_factorisation = false;
  params.engine = engine;
  params.petsc_options = options;
  FlowSolver3 solver(TetMesh::box({0, 0, 0}, {L, H, 0.5}, 6, 3, 2), params, "p2p1");
  auto exact = [&](const Eigen::Vector3d& x, double) -> Eigen::Vector3d {
    return {4 * U * x.y() * (H - x.y()) / (H * H), 0, 0};
  };
  for (const char* g : {"left", "bottom", "top"}) solver.add_dirichlet(g, exact);
  solver.add_symmetry("back");
  solver.add_symmetry("front");
  iterations = solver.solve(1, 1, solver.mesh().nodes, {}).krylov_iterations;
  return solver.solution();
}

TEST(PetscRanks, MumpsAndFieldSplitEqualUmfpack) {
  if (!petsc_available()) GTEST_SKIP() << "built without PETSc";
  std::printf("MPI ranks: %d\n", mpi_world_size());
  if (expected_ranks > 0) {
    EXPECT_EQ(mpi_world_size(), expected_ranks);
  }
  int its = 0;
  const auto lu = poiseuille(LinearEngine::Umfpack, "", its);
  const auto mumps = poiseuille(LinearEngine::Mumps, "", its);
  EXPECT_LT((mumps - lu).lpNorm<Eigen::Infinity>(), 1e-10);
  const auto gmres = poiseuille(LinearEngine::Petsc, "-ksp_rtol 1e-13", its);
  EXPECT_GT(its, 0);
  EXPECT_LT((gmres - lu).lpNorm<Eigen::Infinity>(), 1e-9);
}

// Two BDF2 Newton steps of the channel above on a mesh moved in y (so the ALE mesh velocity,
// the history and the advection all enter the element matrices), MUMPS, with the assembly of
// `mode`: 0 rank 0 alone, 1 every rank's block summed on rank 0, 2 partitioned (each rank keeps
// its cells and fills its rows of the distributed matrix; FlowParameters::partitioned_assembly).
// The solution and the reactions (the forces on the walls) of the last step.
struct Channel {
  Eigen::VectorXd solution, reaction;
  int assembly_ranks = 0;
};
Channel moving_channel(int mode) {
  const double L = 2, H = 1, U = 1.5, pi = 3.141592653589793;
  FlowParameters params;
  params.viscosity = 0.05;
  params.scheme = TimeScheme::BDF2;
  params.newton = true;
  params.max_iterations = 3;
  params.tolerance = 1e-12;
  params.engine = LinearEngine::Mumps;
  params.distributed_assembly = mode > 0;
  params.partitioned_assembly = mode == 2;
  FlowSolver3 solver(TetMesh::box({0, 0, 0}, {L, H, 0.5}, 6, 3, 2), params, "p2p1");
  auto inflow = [&](const Eigen::Vector3d& x, double) -> Eigen::Vector3d {
    return {4 * U * x.y() * (H - x.y()) / (H * H), 0, 0};
  };
  for (const char* g : {"left", "bottom", "top"}) solver.add_dirichlet(g, inflow);
  solver.add_symmetry("back");
  solver.add_symmetry("front");
  for (int step = 1; step <= 2; ++step) {
    Eigen::MatrixX3d x = solver.mesh().nodes;
    for (Eigen::Index i = 0; i < x.rows(); ++i)
      x(i, 1) += 0.03 * step * std::sin(pi * x(i, 0) / L) * std::sin(pi * x(i, 1) / H);
    solver.solve(0.1 * step, 0.1, x, {});
    solver.accept();
  }
  return {solver.solution(), solver.reaction(), solver.assembly_ranks()};
}

TEST(PetscRanks, DistributedAndPartitionedAssembliesEqualRankZerosAlone) {
  if (!petsc_available()) GTEST_SKIP() << "built without PETSc";
  const auto alone = moving_channel(0), summed = moving_channel(1), partitioned = moving_channel(2);
  EXPECT_EQ(alone.assembly_ranks, 1);
  EXPECT_EQ(summed.assembly_ranks, mpi_world_size());  // every rank computes element matrices
  EXPECT_EQ(partitioned.assembly_ranks, mpi_world_size());
  const double u = alone.solution.lpNorm<Eigen::Infinity>(), f = alone.reaction.lpNorm<Eigen::Infinity>();
  EXPECT_GT(u, 1.0);
  EXPECT_GT(f, 1e-3);
  for (const auto* other : {&summed, &partitioned}) {
    EXPECT_LT((other->solution - alone.solution).lpNorm<Eigen::Infinity>(), 1e-12 * u);
    EXPECT_LT((other->reaction - alone.reaction).lpNorm<Eigen::Infinity>(), 1e-10 * f);
  }
}

// The backflow stabilisation, closed form: a uniform flow u = (-U, 0, 0) enters through the
// traction-free face x = L and leaves through x = 0 (prescribed), slip walls. Without the term p =
// 0; with it the open face's traction is beta rho (u.n) u = (beta rho U^2, 0, 0), so p = -beta rho
// U^2 in the whole box (a uniform flow has no viscous stress). On 2 ranks the term comes from
// rank 0 into the partitioned matrix.
TEST(PetscRanks, BackflowStabilisationGivesTheClosedFormPressure) {
  if (!petsc_available()) GTEST_SKIP() << "built without PETSc";
  const double U = 0.8, rho = 1.3, beta = 0.4;
  for (const double b : {0.0, beta}) {
    FlowParameters params;
    params.density = rho;
    params.viscosity = 0.05;
    params.scheme = TimeScheme::Steady;
    params.newton = true;
    params.max_iterations = 4;
    params.tolerance = 1e-12;
    params.engine = LinearEngine::Mumps;
    params.backflow_beta = b;
    FlowSolver3 solver(TetMesh::box({0, 0, 0}, {2, 1, 0.5}, 4, 2, 2), params, "p2p1");
    solver.add_dirichlet("left", [&](const Eigen::Vector3d&, double) -> Eigen::Vector3d { return {-U, 0, 0}; });
    for (const char* g : {"bottom", "top", "back", "front"}) solver.add_symmetry(g);
    solver.add_open_boundary("right");
    solver.solve(1, 0, solver.mesh().nodes, {});
    const double expected = -b * rho * U * U;
    for (const Eigen::Vector3d x : {Eigen::Vector3d(1.0, 0.5, 0.25), Eigen::Vector3d(1.9, 0.2, 0.1)})
      EXPECT_NEAR(solver.pressure_at(x), expected, 1e-9) << "beta " << b << " at " << x.transpose();
  }
}

TEST(PetscRanks, AnInvertedCellOfAnyRanksBlockIsReported) {
  if (!petsc_available()) GTEST_SKIP() << "built without PETSc";
  FlowParameters params;
  params.scheme = TimeScheme::Steady;
  params.engine = LinearEngine::Mumps;
  FlowSolver3 solver(TetMesh::box({0, 0, 0}, {2, 1, 0.5}, 6, 3, 2), params, "p2p1");
  const auto& mesh = solver.mesh();
  // The last cell (in the last rank's block) folded: its first vertex pushed through the
  // opposite face.
  const int e = mesh.cell_count() - 1;
  Eigen::MatrixX3d x = mesh.nodes;
  const Eigen::RowVector3d face = (x.row(mesh.tets(e, 1)) + x.row(mesh.tets(e, 2)) + x.row(mesh.tets(e, 3))) / 3.0;
  x.row(mesh.tets(e, 0)) += 2.5 * (face - x.row(mesh.tets(e, 0)));
  mesh.interpolate_midpoints(x);
  try {
    solver.solve(1, 1, x, {});
    ADD_FAILURE() << "no error for an inverted tetrahedron";
  } catch (const MeshTangled& error) {
    EXPECT_NE(std::string(error.what()).find("10-node tetrahedron"), std::string::npos) << error.what();
  }
}

}  // namespace

int main(int argc, char** argv) {
  if (const int code = start_mpi_ranks(); code >= 0) return code;  // ranks 1..: serve the solves
  ::testing::InitGoogleTest(&argc, argv);
  for (int i = 1; i < argc; ++i)
    if (std::strncmp(argv[i], "--expect-ranks=", 15) == 0) expected_ranks = std::atoi(argv[i] + 15);
  return RUN_ALL_TESTS();
}
