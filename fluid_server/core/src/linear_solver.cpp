// make_linear_solver and the MPI environment (linear_solver.hpp).
#include "fsi/fluid/linear_solver.hpp"

#include <algorithm>
#include <cstdlib>
#include <stdexcept>

#include "fsi/fluid/sparse_lu.hpp"
#ifdef FSI_HAVE_PETSC
#include "petsc_solver.hpp"
#else
#include "mpi_ranks.hpp"
#endif

namespace fsi::fluid {
namespace {

int env_int(const char* a, const char* b, int fallback) {
  for (const char* name : {a, b})
    if (const char* v = std::getenv(name)) return std::atoi(v);
  return fallback;
}

}  // namespace

bool petsc_available() {
#ifdef FSI_HAVE_PETSC
  return true;
#else
  return false;
#endif
}

std::string default_petsc_options(LinearEngine engine) {
#ifdef FSI_HAVE_PETSC
  return petsc_default_options(engine);
#else
  (void)engine;
  return "";
#endif
}

std::unique_ptr<LinearSolver> make_linear_solver(const FlowParameters& params, int dimension,
                                                 std::vector<char> pressure) {
  if (params.engine == LinearEngine::Umfpack) return std::make_unique<SparseLu>(params, dimension == 3);
#ifdef FSI_HAVE_PETSC
  return std::make_unique<PetscSolver>(params, std::move(pressure));
#else
  (void)pressure;
  throw std::invalid_argument(
      "fluid.linear_solver.engine petsc / mumps: this build has no PETSc (install libpetsc-real-dev and "
      "reconfigure; scripts/install-deps.sh)");
#endif
}

int mpi_world_size() { return env_int("OMPI_COMM_WORLD_SIZE", "PMI_SIZE", 1); }
int mpi_world_rank() { return env_int("OMPI_COMM_WORLD_RANK", "PMI_RANK", 0); }

int start_mpi_ranks() {
  if (mpi_world_size() <= 1) return -1;
#ifdef FSI_HAVE_PETSC
  return petsc_start_mpi_ranks();
#else
  if (mpi_world_rank() > 0) return 0;  // nothing to serve: rank 0 refuses the scene
  return -1;
#endif
}

#ifndef FSI_HAVE_PETSC
// Without PETSc there is one rank (mpi_ranks.hpp).
namespace ranks {
bool on_command(int, Handler) { return false; }
int size() { return 1; }
int rank() { return 0; }
bool command(int, int) { return false; }
void broadcast(double*, std::size_t) {}
void broadcast(int*, std::size_t) {}
void broadcast(std::string&) {}
void sum_to_root(double*, std::size_t) {}
void gather_to_root(const double* mine, int count, double* all) { std::copy(mine, mine + count, all); }
void fill_system(int, const Part&, const std::vector<int>&, const std::vector<double>&) {
  throw std::logic_error("fill_system: this build has no PETSc");
}
}  // namespace ranks
#endif

}  // namespace fsi::fluid
