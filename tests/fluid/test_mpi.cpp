// The PETSc engines on however many MPI ranks this test runs on (ctest: 1 rank, and 2 ranks
// under mpirun: fluid.mpi_two_ranks): the 3D plane Poiseuille problem of test_tet.cpp solved by
// MUMPS and by the field-split GMRES equals the UMFPACK solution on rank 0. Ranks other than 0
// serve the PETSc solves (start_mpi_ranks), as in fluid_server.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>

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
  if (expected_ranks > 0) EXPECT_EQ(mpi_world_size(), expected_ranks);
  int its = 0;
  const auto lu = poiseuille(LinearEngine::Umfpack, "", its);
  const auto mumps = poiseuille(LinearEngine::Mumps, "", its);
  EXPECT_LT((mumps - lu).lpNorm<Eigen::Infinity>(), 1e-10);
  const auto gmres = poiseuille(LinearEngine::Petsc, "-ksp_rtol 1e-13", its);
  EXPECT_GT(its, 0);
  EXPECT_LT((gmres - lu).lpNorm<Eigen::Infinity>(), 1e-9);
}

}  // namespace

int main(int argc, char** argv) {
  if (const int code = start_mpi_ranks(); code >= 0) return code;  // ranks 1..: serve the solves
  ::testing::InitGoogleTest(&argc, argv);
  for (int i = 1; i < argc; ++i)
    if (std::strncmp(argv[i], "--expect-ranks=", 15) == 0) expected_ranks = std::atoi(argv[i] + 15);
  return RUN_ALL_TESTS();
}
