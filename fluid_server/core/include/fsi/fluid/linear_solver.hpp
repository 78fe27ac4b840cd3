#pragma once
// The fluid's linear-algebra engine behind one interface (FlowParameters::engine):
//   umfpack - SparseLu (sparse_lu.hpp): UMFPACK LU, its factors reused as a BiCGSTAB
//             preconditioner; the 2D default, unchanged (umfpack_di_*; 3D: umfpack_dl_*).
//   petsc   - a PETSc KSP (default: GMRES, PCFIELDSPLIT Schur with ILU(0) on the velocity block
//             and BoomerAMG on the selfp Schur complement), its preconditioner reused while it works.
//   mumps   - MUMPS through PETSc (-ksp_type preonly -pc_type lu -pc_factor_mat_solver_type mumps).
// Both PETSc engines take further PETSc options (FlowParameters::petsc_options) after their
// defaults; an option the solver does not use is an error naming it. PETSc (and MPI) is
// initialised only when a PETSc engine is made: a UMFPACK fluid never touches it.
//
// MPI: a fluid_server started by mpirun with more than one rank calls start_mpi_ranks() first;
// rank 0 runs the fluid (assembly, protocol, output) and every PETSc solve distributes the matrix
// by rows (MPIAIJ) over all ranks, which run the KSP together; the other ranks only serve solves.
#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "fsi/common/state.hpp"
#include "fsi/fluid/flow_solver.hpp"

namespace fsi::fluid {

class LinearSolver {
 public:
  virtual ~LinearSolver() = default;
  // Solves A x = b (the guess may be empty). Adds its set-up (factorisation or preconditioner)
  // and solve times and counts to `report`. Throws fsi::SolverError (prefixed with `where`) when
  // the solve fails. `time_coefficient`: alpha0 / dt (0 when steady); set-ups of a matrix with
  // another coefficient are not reused.
  virtual Eigen::VectorXd solve(const Eigen::SparseMatrix<double>& A, const Eigen::VectorXd& b,
                                const Eigen::VectorXd& guess, StepReport& report, const std::string& where,
                                double time_coefficient) = 0;
  // The PETSc engines on several MPI ranks: the id by which every rank fills this solver's
  // distributed matrix itself (the partitioned assembly, mpi_ranks.hpp's fill_system), or -1.
  virtual int partition_id() const { return -1; }
  // Solves the system the ranks filled last (partition_id() >= 0; `unknowns` of it), as solve().
  virtual Eigen::VectorXd solve_filled(int unknowns, const Eigen::VectorXd& guess, StepReport& report,
                                       const std::string& where, double time_coefficient) {
    (void)unknowns, (void)guess, (void)report, (void)time_coefficient;
    throw std::logic_error(where + ": this linear solver has no distributed matrix");
  }
  // Checkpoints: the next solve sets up afresh; the state of the engine's decisions.
  virtual void discard_factors() = 0;
  virtual void save_state(StateArchive& state, const std::string& prefix) const = 0;
  virtual void load_state(const StateArchive& state, const std::string& prefix) = 0;
};

// The engine of `params`; `pressure[i]` != 0 marks unknown i as a pressure (the field split);
// `dimension` 3 makes UMFPACK use its 64-bit API. std::invalid_argument for a PETSc engine in a
// build without PETSc.
std::unique_ptr<LinearSolver> make_linear_solver(const FlowParameters& params, int dimension,
                                                 std::vector<char> pressure);

// The engines' default PETSc options (petsc, mumps); the scene's options come after them.
std::string default_petsc_options(LinearEngine engine);
bool petsc_available();  // this build has the PETSc engines

// The MPI world this process was started in, from the launcher's environment (Open MPI's
// OMPI_COMM_WORLD_SIZE / _RANK, MPICH's PMI_SIZE / PMI_RANK): 1 and 0 without mpirun. No MPI call.
int mpi_world_size();
int mpi_world_rank();
// For fluid_server under mpirun with more than one rank, before anything else: initialises
// PETSc (and MPI) on every rank. Ranks other than 0 serve rank 0's PETSc solves until it quits
// (at its exit) and return their exit code; rank 0 gets -1 and runs the fluid.
int start_mpi_ranks();

}  // namespace fsi::fluid
