#pragma once
// The fluid's UMFPACK engine (linear_solver.hpp), shared by both discretisations: UMFPACK with one symbolic
// analysis per sparsity pattern (METIS or AMD ordering), a numeric factorisation per matrix,
// or - with reuse_factorisation - BiCGSTAB preconditioned by the factors of an earlier
// matrix, refactorising only when that preconditioner has gone stale.
//
// Every decision is deterministic (a function of the matrices, never of wall-clock time), so
// two runs of the same scene, and a run resumed from a checkpoint, take the same path:
//  - ordering auto: both orderings are analysed and factorised on the first matrix and the one
//    whose factorisation needs fewer flops (UMFPACK's count, Info[UMFPACK_FLOPS]) is kept;
//  - adaptive_refactorisation: a cost model in flops. A factorisation costs its UMFPACK flop
//    count, divided by kFactorFlopSpeedup (dense frontal BLAS-3 flops run that much faster than
//    the memory-bound flops of triangular solves and matrix-vector products), plus one solve
//    (Info[UMFPACK_SOLVE_FLOPS]); a BiCGSTAB solve costs its iterations times two
//    applications of the factors, two products with A (2 nnz(A) flops each) and the vector
//    operations. As soon as one Krylov solve costs more than the average per solve of the
//    current factors (their factorisation included), the factors are marked stale: the next
//    solve refactorises (that minimises the cost per solve).
//  - factors of a matrix with another time-derivative coefficient (alpha0 / dt: the BDF1 start
//    before BDF2, a new step size) are not reused: the mass term changed by up to 50 % and
//    BiCGSTAB would need 3-4 iterations where fresh factors need 1-2, for as long as the
//    cost rule above, which only sees costs rising, keeps them.
//  - discard_factors() (called when a checkpoint is saved) drops the factors and the symbolic
//    analysis but keeps the chosen ordering: the next solve starts a fresh cycle, exactly as
//    a SparseLu restored from that checkpoint does.
//
//   SparseLu lu(params);
//   x = lu.solve(A, b, guess, report, "fluid step at t = 0.1");   // same pattern every call
#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <memory>
#include <string>
#include <utility>

#include "fsi/common/state.hpp"
#include "fsi/fluid/flow_solver.hpp"
#include "fsi/fluid/linear_solver.hpp"

namespace fsi::fluid {

class SparseLu final : public LinearSolver {
 public:
  // Wall time per flop of the triangular solves and products of a Krylov solve over that of a
  // factorisation: 1.16-1.28e-9 s against 4.1-4.3e-10 s, measured on DFG 2D-2 P1/P1 (39k
  // unknowns) and DFG 2D-3 P2/P1 (35.8k). Only the decisions depend on it, not the results'
  // accuracy; the same constant on every machine keeps them reproducible.
  static constexpr double kFactorFlopSpeedup = 3.0;

  // long_indices: UMFPACK's 64-bit API (umfpack_dl_*; the 3D fluid), else umfpack_di_*.
  explicit SparseLu(const FlowParameters& params, bool long_indices = false);
  ~SparseLu() override;
  SparseLu(SparseLu&&) noexcept;
  SparseLu& operator=(SparseLu&&) noexcept;
  // Adds its factorisation / solve times and counts to `report`. Throws fsi::SolverError
  // (prefixed with `where`) when the matrix is singular or the solution not finite.
  // `time_coefficient` (the solvers pass alpha0 / dt, 0 when steady): factors of a matrix with
  // another coefficient of the time derivative (the first BDF2 step after the BDF1 start, a
  // new step size) are not reused.
  Eigen::VectorXd solve(const Eigen::SparseMatrix<double>& A, const Eigen::VectorXd& b, const Eigen::VectorXd& guess,
                        StepReport& report, const std::string& where, double time_coefficient = 0) override;
  // The ordering in use (Ordering::Auto picks it at the first factorisation) and, for Auto,
  // UMFPACK's flop counts of the first factorisation with AMD and with METIS (0, 0 otherwise).
  Ordering ordering() const;
  std::pair<double, double> measured_orderings() const;

  // Checkpoints. discard_factors(): the next solve analyses and factorises afresh (with the
  // ordering already chosen). save_state() writes the chosen ordering (prefix + "ordering":
  // "amd", "metis", or "auto" before the first factorisation) and the auto trial's flop
  // counts; load_state() on a fresh SparseLu makes it use that ordering without a new trial
  // (fsi::StateError if the parameters fix a different one).
  void discard_factors() override;
  void save_state(StateArchive& state, const std::string& prefix) const override;
  void load_state(const StateArchive& state, const std::string& prefix) override;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace fsi::fluid
