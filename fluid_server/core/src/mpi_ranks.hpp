#pragma once
// The fluid's MPI ranks as the rest of fsi_fluid sees them, without MPI's headers: rank 0 runs
// the solver and sends commands; every other rank waits in the PETSc engine's serve loop and
// runs the handler registered for each command (the linear solves are the engine's own
// commands; the distributed assembly registers its own). After a command both sides make the
// same collective calls below, in the same order. Implemented in petsc_solver.cpp (the one
// source that sees MPI); a build without PETSc has one rank and every call is a no-op.
#include <cstddef>
#include <string>
#include <vector>

namespace fsi::fluid::ranks {

// Commands other than the linear solver's (which uses 0-3).
enum Command : int { kAssemblyCreate = 16, kAssemble = 17, kAssemblyDestroy = 18, kAssemblyReaction = 19 };

// Ranks > 0: the function called for `command` (with rank 0's id). Register before serving
// (at static initialisation of the registering source).
using Handler = void (*)(int command, int id);
bool on_command(int command, Handler handler);

// The ranks of MPI_COMM_WORLD once MPI is up (1 before, and without PETSc).
int size();
int rank();

// Rank 0: tells the waiting ranks to run `command` with `id`. False (nothing sent) on one rank
// or once MPI is finalised.
bool command(int command, int id);

// Collective: rank 0's values reach every rank (counts equal on all ranks).
void broadcast(double* data, std::size_t count);
void broadcast(int* data, std::size_t count);
void broadcast(std::string& text);
// Collective: rank 0 gets the sum over the ranks in `data` (in place); the others send theirs.
void sum_to_root(double* data, std::size_t count);
// Collective: rank 0 gets every rank's `count` values in rank order in `all` (size() * count).
void gather_to_root(const double* mine, int count, double* all);

// ---- A linear system distributed by rows, filled by every rank (the partitioned assembly) ----
// `id`: the PETSc solver's (LinearSolver::partition_id).

// One rank's part of the matrix and right-hand side: a square matrix on the rank's own unknowns
// (CSC with local indices) and the map from its local unknowns to the system's; on rank 0 also
// entries of its own (the interface terms: rows and columns of the system; a pattern fixed from
// the first fill on, values every fill) and right-hand side entries (any, every fill).
struct Part {
  int unknowns = 0;  // of the whole system
  int columns = 0;   // local unknowns
  const int* colptr = nullptr;
  const int* rowind = nullptr;
  const double* values = nullptr;
  const int* global = nullptr;  // local unknown -> the system's
  const double* rhs = nullptr;  // per local unknown
  int extra_count = 0;
  const int* extra_rows = nullptr;
  const int* extra_cols = nullptr;
  const double* extra_values = nullptr;
  int extra_rhs_count = 0;
  const int* extra_rhs_rows = nullptr;
  const double* extra_rhs_values = nullptr;
};

// Collective: the system's matrix and right-hand side become the sum of every rank's part; then
// the rows `rows` (rank 0's list; the others pass none) become identity rows with right-hand side
// `values`. The first fill (and one with another number of unknowns) takes the pattern from the
// parts (PETSc's COO assembly: later fills only move values). Throws std::runtime_error with
// PETSc's message on a failure (every rank alike).
void fill_system(int id, const Part& part, const std::vector<int>& rows, const std::vector<double>& values);

}  // namespace fsi::fluid::ranks
