#pragma once
// The fluid's MPI ranks as the rest of fsi_fluid sees them, without MPI's headers: rank 0 runs
// the solver and sends commands; every other rank waits in the PETSc engine's serve loop and
// runs the handler registered for each command (the linear solves are the engine's own
// commands; the distributed assembly registers its own). After a command both sides make the
// same collective calls below, in the same order. Implemented in petsc_solver.cpp (the one
// source that sees MPI); a build without PETSc has one rank and every call is a no-op.
#include <cstddef>
#include <string>

namespace fsi::fluid::ranks {

// Commands other than the linear solver's (which uses 0-3).
enum Command : int { kAssemblyCreate = 16, kAssemble = 17, kAssemblyDestroy = 18 };

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

}  // namespace fsi::fluid::ranks
