#include "fsi/fluid/sparse_lu.hpp"

#include <Eigen/IterativeLinearSolvers>
#include <Eigen/UmfPackSupport>
#include <fmt/format.h>

#include <chrono>

#include "fsi/common/log.hpp"
#include "fsi/common/solver_model.hpp"

namespace fsi::fluid {
namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }
using LuSolver = Eigen::UmfPackLU<Eigen::SparseMatrix<double>>;

// The factors of an earlier matrix used as a preconditioner (Eigen preconditioner concept).
class FrozenLuPreconditioner {
 public:
  FrozenLuPreconditioner() = default;
  void set(const LuSolver* lu) { lu_ = lu; }
  template <class M> FrozenLuPreconditioner& analyzePattern(const M&) { return *this; }
  template <class M> FrozenLuPreconditioner& factorize(const M&) { return *this; }
  template <class M> FrozenLuPreconditioner& compute(const M&) { return *this; }
  template <class R> Eigen::VectorXd solve(const Eigen::MatrixBase<R>& b) const { return lu_->solve(b); }
  Eigen::ComputationInfo info() const { return Eigen::Success; }

 private:
  const LuSolver* lu_ = nullptr;
};

}  // namespace

struct SparseLu::Impl {
  FlowParameters params;
  std::unique_ptr<LuSolver> lu = std::make_unique<LuSolver>();
  bool analysed = false;
  bool factorised = false;
  bool stale = false;  // the factors precondition poorly: refactorise at the next solve
  Ordering chosen = Ordering::Amd;
  double cycle_seconds = 0;  // factorisation + solves since the last factorisation
  int cycle_solves = 0;
  std::pair<double, double> measured{0, 0};  // auto: factorisation seconds with AMD, METIS
};

SparseLu::SparseLu(const FlowParameters& params) : impl_(std::make_unique<Impl>()) { impl_->params = params; }
SparseLu::~SparseLu() = default;
SparseLu::SparseLu(SparseLu&&) noexcept = default;
SparseLu& SparseLu::operator=(SparseLu&&) noexcept = default;

Eigen::VectorXd SparseLu::solve(const Eigen::SparseMatrix<double>& A, const Eigen::VectorXd& b, const Eigen::VectorXd& guess,
                                StepReport& report, const std::string& where) {
  auto& s = *impl_;
  const auto& p = s.params;
  Eigen::VectorXd x;
  if (p.reuse_factorisation && s.factorised && !s.stale) {
    const auto t_solve = Clock::now();
    Eigen::BiCGSTAB<Eigen::SparseMatrix<double>, FrozenLuPreconditioner> krylov;
    krylov.preconditioner().set(s.lu.get());
    krylov.setTolerance(p.krylov_tolerance);
    krylov.setMaxIterations(p.krylov_max_iterations);
    krylov.compute(A);
    x = guess.size() == b.size() ? Eigen::VectorXd(krylov.solveWithGuess(b, guess)) : Eigen::VectorXd(krylov.solve(b));
    const double seconds = seconds_since(t_solve);
    report.solve_seconds += seconds;
    if (krylov.info() == Eigen::Success && x.allFinite()) {
      report.krylov_iterations += static_cast<int>(krylov.iterations());
      if (krylov.iterations() > p.krylov_refactor_iterations) s.stale = true;
      // Cost-based refactorisation: the factorisation's cost is shared by every solve that
      // reuses it; once one more Krylov solve costs more than that running average (factorisation
      // + its solves, per solve), a fresh factorisation is the cheaper next step.
      s.cycle_seconds += seconds;
      ++s.cycle_solves;
      if (p.adaptive_refactorisation && seconds > s.cycle_seconds / s.cycle_solves) s.stale = true;
      return x;
    }
  }
  const auto t_factor = Clock::now();
  if (!s.analysed) {
    auto analyse = [&](LuSolver& lu, Ordering ordering) {
      lu.umfpackControl()(UMFPACK_IRSTEP) = p.umfpack_irstep;
      lu.umfpackControl()(UMFPACK_ORDERING) = ordering == Ordering::Metis ? UMFPACK_ORDERING_METIS : UMFPACK_ORDERING_AMD;
      lu.umfpackControl()(UMFPACK_STRATEGY) = p.strategy == LuStrategy::Symmetric     ? UMFPACK_STRATEGY_SYMMETRIC
                                              : p.strategy == LuStrategy::Unsymmetric ? UMFPACK_STRATEGY_UNSYMMETRIC
                                                                                      : UMFPACK_STRATEGY_AUTO;
      lu.analyzePattern(A);
    };
    if (p.ordering == Ordering::Auto) {
      // Measure both orderings on the first matrix (analysis + factorisation) and keep the
      // one whose factorisation is faster: every later factorisation reuses its analysis.
      auto other = std::make_unique<LuSolver>();
      analyse(*s.lu, Ordering::Amd);
      const auto t_amd = Clock::now();
      s.lu->factorize(A);
      const double amd = seconds_since(t_amd);
      analyse(*other, Ordering::Metis);
      const auto t_metis = Clock::now();
      other->factorize(A);
      const double metis = seconds_since(t_metis);
      s.chosen = metis < amd ? Ordering::Metis : Ordering::Amd;
      s.measured = {amd, metis};
      if (s.chosen == Ordering::Metis) std::swap(s.lu, other);
      fsi::logger("fluid")->info("linear solver: ordering auto chose {} (first factorisation of {} unknowns: AMD {:.3f} s, "
                                 "METIS {:.3f} s)",
                                 s.chosen == Ordering::Metis ? "METIS" : "AMD", A.rows(), amd, metis);
    } else {
      analyse(*s.lu, p.ordering);
      s.chosen = p.ordering;
    }
    s.analysed = true;
    if (p.ordering != Ordering::Auto) s.lu->factorize(A);
  } else {
    s.lu->factorize(A);
  }
  if (s.lu->info() != Eigen::Success)
    throw SolverError(fmt::format("{}: UMFPACK factorisation failed (singular matrix?: check that the pressure is fixed "
                                  "by an outlet or a pressure reference)",
                                  where));
  s.factorised = true;
  s.stale = false;
  ++report.factorisations;
  report.factor_seconds += seconds_since(t_factor);
  const auto t_solve = Clock::now();
  x = s.lu->solve(b);
  report.solve_seconds += seconds_since(t_solve);
  s.cycle_seconds = seconds_since(t_factor);
  s.cycle_solves = 1;
  if (!x.allFinite()) throw SolverError(fmt::format("{}: the solution is not finite", where));
  return x;
}

}  // namespace fsi::fluid

namespace fsi::fluid {
Ordering SparseLu::ordering() const { return impl_->chosen; }
std::pair<double, double> SparseLu::measured_orderings() const { return impl_->measured; }
}  // namespace fsi::fluid
