#pragma once
// The fluid's linear solve, shared by both discretisations: UMFPACK with one symbolic
// analysis per sparsity pattern (METIS or AMD ordering), a numeric factorisation per matrix,
// (ordering auto: both tried on the first matrix, the faster kept),
// or - with reuse_factorisation - BiCGSTAB preconditioned by the factors of an earlier
// matrix, refactorising only when that preconditioner has gone stale.
//
//   SparseLu lu(params);
//   x = lu.solve(A, b, guess, report, "fluid step at t = 0.1");   // same pattern every call
#include <Eigen/Core>
#include <Eigen/SparseCore>

#include <memory>
#include <string>
#include <utility>

#include "fsi/fluid/flow_solver.hpp"

namespace fsi::fluid {

class SparseLu {
 public:
  explicit SparseLu(const FlowParameters& params);
  ~SparseLu();
  SparseLu(SparseLu&&) noexcept;
  SparseLu& operator=(SparseLu&&) noexcept;
  // Adds its factorisation / solve times and counts to `report`. Throws fsi::SolverError
  // (prefixed with `where`) when the matrix is singular or the solution not finite.
  Eigen::VectorXd solve(const Eigen::SparseMatrix<double>& A, const Eigen::VectorXd& b, const Eigen::VectorXd& guess,
                        StepReport& report, const std::string& where);
  // The ordering in use (Ordering::Auto picks it at the first factorisation) and, for Auto,
  // the measured factorisation seconds with AMD and with METIS (0, 0 otherwise).
  Ordering ordering() const;
  std::pair<double, double> measured_orderings() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace fsi::fluid
