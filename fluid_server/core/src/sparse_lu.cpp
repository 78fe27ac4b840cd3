#include "fsi/fluid/sparse_lu.hpp"

#include <fmt/format.h>

#include <Eigen/IterativeLinearSolvers>
#include <Eigen/UmfPackSupport>
#include <chrono>
#include <type_traits>

#include "fsi/common/log.hpp"
#include "fsi/common/solver_model.hpp"

namespace fsi::fluid {
namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

// UMFPACK's status codes by name (umfpack.h), for errors.
const char* umfpack_status_name(double status) {
  switch (static_cast<int>(status)) {
    case UMFPACK_OK:
      return "UMFPACK_OK";
    case UMFPACK_WARNING_singular_matrix:
      return "UMFPACK_WARNING_singular_matrix";
    case UMFPACK_WARNING_determinant_underflow:
      return "UMFPACK_WARNING_determinant_underflow";
    case UMFPACK_WARNING_determinant_overflow:
      return "UMFPACK_WARNING_determinant_overflow";
    case UMFPACK_ERROR_out_of_memory:
      return "UMFPACK_ERROR_out_of_memory";
    case UMFPACK_ERROR_invalid_Numeric_object:
      return "UMFPACK_ERROR_invalid_Numeric_object";
    case UMFPACK_ERROR_invalid_Symbolic_object:
      return "UMFPACK_ERROR_invalid_Symbolic_object";
    case UMFPACK_ERROR_argument_missing:
      return "UMFPACK_ERROR_argument_missing";
    case UMFPACK_ERROR_n_nonpositive:
      return "UMFPACK_ERROR_n_nonpositive";
    case UMFPACK_ERROR_invalid_matrix:
      return "UMFPACK_ERROR_invalid_matrix";
    case UMFPACK_ERROR_different_pattern:
      return "UMFPACK_ERROR_different_pattern";
    case UMFPACK_ERROR_invalid_system:
      return "UMFPACK_ERROR_invalid_system";
    case UMFPACK_ERROR_invalid_permutation:
      return "UMFPACK_ERROR_invalid_permutation";
    case UMFPACK_ERROR_internal_error:
      return "UMFPACK_ERROR_internal_error";
    case UMFPACK_ERROR_file_IO:
      return "UMFPACK_ERROR_file_IO";
    default:
      return "unknown UMFPACK status";
  }
}

// UMFPACK behind one interface for its two integer sizes: umfpack_di_* (32-bit indices, the 2D
// fluid) and umfpack_dl_* (64-bit, the 3D fluid: the 32-bit API runs out of index space on
// large 3D factors). Info (flop and nonzero counts, the status) readable.
class LuBackend {
 public:
  virtual ~LuBackend() = default;
  virtual Eigen::Array<double, UMFPACK_CONTROL, 1>& control() = 0;
  virtual void analyse(const Eigen::SparseMatrix<double>& A) = 0;
  virtual void factorize(const Eigen::SparseMatrix<double>& A) = 0;
  virtual bool ok() const = 0;
  virtual double info(int entry) const = 0;
  virtual Eigen::VectorXd solve(const Eigen::VectorXd& b) const = 0;
};

template <class Index>
class UmfpackBackend final : public LuBackend {
  using Matrix = Eigen::SparseMatrix<double, Eigen::ColMajor, Index>;
  class Lu : public Eigen::UmfPackLU<Matrix> {
   public:
    double umfpack_info(int entry) const { return this->m_umfpackInfo(entry); }
  };

 public:
  Eigen::Array<double, UMFPACK_CONTROL, 1>& control() override { return lu_.umfpackControl(); }
  void analyse(const Eigen::SparseMatrix<double>& A) override {
    if constexpr (std::is_same_v<Index, int>) {
      lu_.analyzePattern(A);
    } else {
      const Matrix copy = A;
      lu_.analyzePattern(copy);
    }
  }
  void factorize(const Eigen::SparseMatrix<double>& A) override {
    if constexpr (std::is_same_v<Index, int>) {
      lu_.factorize(A);
    } else {
      const Matrix copy = A;
      lu_.factorize(copy);
    }
  }
  bool ok() const override { return lu_.info() == Eigen::Success; }
  double info(int entry) const override { return lu_.umfpack_info(entry); }
  Eigen::VectorXd solve(const Eigen::VectorXd& b) const override { return lu_.solve(b); }

 private:
  Lu lu_;
};

std::unique_ptr<LuBackend> make_backend(bool long_indices) {
  if (long_indices) return std::make_unique<UmfpackBackend<SuiteSparse_long>>();
  return std::make_unique<UmfpackBackend<int>>();
}

// The factors of an earlier matrix used as a preconditioner (Eigen preconditioner concept).
class FrozenLuPreconditioner {
 public:
  FrozenLuPreconditioner() = default;
  void set(const LuBackend* lu) { lu_ = lu; }
  template <class M>
  FrozenLuPreconditioner& analyzePattern(const M&) {
    return *this;
  }
  template <class M>
  FrozenLuPreconditioner& factorize(const M&) {
    return *this;
  }
  template <class M>
  FrozenLuPreconditioner& compute(const M&) {
    return *this;
  }
  template <class R>
  Eigen::VectorXd solve(const Eigen::MatrixBase<R>& b) const {
    return lu_->solve(b);
  }
  Eigen::ComputationInfo info() const { return Eigen::Success; }

 private:
  const LuBackend* lu_ = nullptr;
};

const char* ordering_name(Ordering o) { return o == Ordering::Metis ? "metis" : o == Ordering::Amd ? "amd" : "auto"; }

}  // namespace

struct SparseLu::Impl {
  FlowParameters params;
  bool long_indices = false;  // umfpack_dl_* (see LuBackend)
  std::unique_ptr<LuBackend> lu;
  bool analysed = false;
  bool factorised = false;
  bool stale = false;                // the factors precondition poorly: refactorise at the next solve
  double time_coefficient = 0;       // alpha0 / dt of the factorised matrix
  Ordering chosen = Ordering::Auto;  // Auto until the first analysis decides (or a fixed one)
  // Cost model of the current factors (flops, see sparse_lu.hpp): one application of the
  // factors, one product with A, and the cost of the cycle so far (factorisation + solves).
  double apply_flops = 0, product_flops = 0;
  double cycle_flops = 0;
  int cycle_solves = 0;
  std::pair<double, double> measured{0, 0};  // auto: UMFPACK factorisation flops with AMD, METIS
};

SparseLu::SparseLu(const FlowParameters& params, bool long_indices) : impl_(std::make_unique<Impl>()) {
  impl_->params = params;
  impl_->long_indices = long_indices;
  impl_->lu = make_backend(long_indices);
  if (params.ordering != Ordering::Auto) impl_->chosen = params.ordering;
}
SparseLu::~SparseLu() = default;
SparseLu::SparseLu(SparseLu&&) noexcept = default;
SparseLu& SparseLu::operator=(SparseLu&&) noexcept = default;

Eigen::VectorXd SparseLu::solve(const Eigen::SparseMatrix<double>& A, const Eigen::VectorXd& b,
                                const Eigen::VectorXd& guess, StepReport& report, const std::string& where,
                                double time_coefficient) {
  auto& s = *impl_;
  const auto& p = s.params;
  Eigen::VectorXd x;
  if (s.factorised && time_coefficient != s.time_coefficient) s.stale = true;
  if (p.reuse_factorisation && s.factorised && !s.stale) {
    const auto t_solve = Clock::now();
    Eigen::BiCGSTAB<Eigen::SparseMatrix<double>, FrozenLuPreconditioner> krylov;
    krylov.preconditioner().set(s.lu.get());
    krylov.setTolerance(p.krylov_tolerance);
    krylov.setMaxIterations(p.krylov_max_iterations);
    krylov.compute(A);
    x = guess.size() == b.size() ? Eigen::VectorXd(krylov.solveWithGuess(b, guess)) : Eigen::VectorXd(krylov.solve(b));
    report.solve_seconds += seconds_since(t_solve);
    if (krylov.info() == Eigen::Success && x.allFinite()) {
      const auto iterations = static_cast<double>(krylov.iterations());
      report.krylov_iterations += static_cast<int>(krylov.iterations());
      if (krylov.iterations() > p.krylov_refactor_iterations) s.stale = true;
      // Cost-based refactorisation: the factorisation's cost is shared by every solve that
      // reuses it; once one more Krylov solve costs more than that running average (factorisation
      // + its solves, per solve), a fresh factorisation is the cheaper next step. Costs in
      // flops (BiCGSTAB: one product with A, then per iteration two applications of the
      // factors, two products and ~20 n flops of vector operations).
      const double cost = s.product_flops +
                          iterations * (2 * s.apply_flops + 2 * s.product_flops + 20.0 * static_cast<double>(A.rows()));
      s.cycle_flops += cost;
      ++s.cycle_solves;
      if (p.adaptive_refactorisation && cost > s.cycle_flops / s.cycle_solves) s.stale = true;
      return x;
    }
  }
  const auto t_factor = Clock::now();
  if (!s.analysed) {
    auto analyse = [&](LuBackend& lu, Ordering ordering) {
      lu.control()(UMFPACK_IRSTEP) = p.umfpack_irstep;
      lu.control()(UMFPACK_ORDERING) = ordering == Ordering::Metis ? UMFPACK_ORDERING_METIS : UMFPACK_ORDERING_AMD;
      lu.control()(UMFPACK_STRATEGY) = p.strategy == LuStrategy::Symmetric     ? UMFPACK_STRATEGY_SYMMETRIC
                                       : p.strategy == LuStrategy::Unsymmetric ? UMFPACK_STRATEGY_UNSYMMETRIC
                                                                               : UMFPACK_STRATEGY_AUTO;
      lu.analyse(A);
    };
    if (s.chosen == Ordering::Auto) {
      // Factorise the first matrix with both orderings and keep the one whose factorisation
      // needs fewer flops (UMFPACK's count: deterministic, unlike timings); every later
      // factorisation reuses its analysis.
      auto other = make_backend(s.long_indices);
      const auto t_amd = Clock::now();
      analyse(*s.lu, Ordering::Amd);
      s.lu->factorize(A);
      const double amd_seconds = seconds_since(t_amd);
      const auto t_metis = Clock::now();
      analyse(*other, Ordering::Metis);
      other->factorize(A);
      const double metis_seconds = seconds_since(t_metis);
      const bool amd_ok = s.lu->ok(), metis_ok = other->ok();
      const double amd = s.lu->info(UMFPACK_FLOPS), metis = other->info(UMFPACK_FLOPS);
      s.chosen = metis_ok && (!amd_ok || metis < amd) ? Ordering::Metis : Ordering::Amd;
      s.measured = {amd, metis};
      if (s.chosen == Ordering::Metis) std::swap(s.lu, other);
      const LuBackend& amd_lu = s.chosen == Ordering::Metis ? *other : *s.lu;
      const LuBackend& metis_lu = s.chosen == Ordering::Metis ? *s.lu : *other;
      fsi::logger("fluid")->info(
          "linear solver: ordering auto chose {} (first factorisation of {} unknowns: AMD {:.3g} "
          "flops, nnz(L+U) {:.3g}, {:.3f} s; METIS {:.3g} flops, nnz(L+U) {:.3g}, {:.3f} s)",
          s.chosen == Ordering::Metis ? "METIS" : "AMD", A.rows(), amd,
          amd_lu.info(UMFPACK_LNZ) + amd_lu.info(UMFPACK_UNZ), amd_seconds, metis,
          metis_lu.info(UMFPACK_LNZ) + metis_lu.info(UMFPACK_UNZ), metis_seconds);
    } else {
      analyse(*s.lu, s.chosen);
      s.lu->factorize(A);
    }
    s.analysed = true;
  } else {
    s.lu->factorize(A);
  }
  if (!s.lu->ok()) {
    const double status = s.lu->info(UMFPACK_STATUS);
    if (static_cast<int>(status) == UMFPACK_WARNING_singular_matrix)
      throw SolverError(fmt::format(
          "{}: UMFPACK factorisation failed: {} ({}): the matrix is singular (check that the pressure is fixed "
          "by an outlet or a pressure reference)",
          where, umfpack_status_name(status), status));
    throw SolverError(fmt::format(
        "{}: UMFPACK ({}) factorisation of {} unknowns failed: {} ({}, peak memory {:.3g} GB)", where,
        s.long_indices ? "umfpack_dl, 64-bit indices" : "umfpack_di, 32-bit indices", A.rows(),
        umfpack_status_name(status), status, s.lu->info(UMFPACK_PEAK_MEMORY) * s.lu->info(UMFPACK_SIZE_OF_UNIT) / 1e9));
  }
  const double factor_flops = s.lu->info(UMFPACK_FLOPS);
  const double lu_nonzeros = s.lu->info(UMFPACK_LNZ) + s.lu->info(UMFPACK_UNZ);
  s.factorised = true;
  s.stale = false;
  s.time_coefficient = time_coefficient;
  ++report.factorisations;
  report.factor_seconds += seconds_since(t_factor);
  const auto t_solve = Clock::now();
  x = s.lu->solve(b);
  report.solve_seconds += seconds_since(t_solve);
  const double solve_flops = s.lu->info(UMFPACK_SOLVE_FLOPS);
  s.apply_flops = solve_flops > 0 ? solve_flops : 2 * lu_nonzeros;
  s.product_flops = 2.0 * static_cast<double>(A.nonZeros());
  s.cycle_flops = factor_flops / kFactorFlopSpeedup + s.apply_flops;
  s.cycle_solves = 1;
  if (!x.allFinite()) throw SolverError(fmt::format("{}: the solution is not finite", where));
  return x;
}

void SparseLu::discard_factors() {
  auto& s = *impl_;
  s.lu = make_backend(s.long_indices);
  s.analysed = s.factorised = s.stale = false;
  s.apply_flops = s.product_flops = s.cycle_flops = 0;
  s.cycle_solves = 0;
}

void SparseLu::save_state(StateArchive& state, const std::string& prefix) const {
  const auto& s = *impl_;
  state.put(prefix + "ordering", std::string(ordering_name(s.chosen)));
  state.put(prefix + "auto_trial_flops", std::vector<double>{s.measured.first, s.measured.second});
}

void SparseLu::load_state(const StateArchive& state, const std::string& prefix) {
  auto& s = *impl_;
  const std::string name = state.text(prefix + "ordering");
  Ordering saved;
  if (name == "amd")
    saved = Ordering::Amd;
  else if (name == "metis")
    saved = Ordering::Metis;
  else if (name == "auto")
    saved = Ordering::Auto;
  else
    throw StateError(fmt::format("entry '{}ordering' is '{}', expected amd, metis or auto", prefix, name));
  if (s.params.ordering != Ordering::Auto && saved != Ordering::Auto && saved != s.params.ordering)
    throw StateError(fmt::format("entry '{}ordering' is '{}' but this configuration fixes linear_solver.ordering: {}",
                                 prefix, name, ordering_name(s.params.ordering)));
  const Eigen::VectorXd trial = state.vector(prefix + "auto_trial_flops", 2);
  discard_factors();
  if (saved != Ordering::Auto) s.chosen = saved;
  s.measured = {trial(0), trial(1)};
}

Ordering SparseLu::ordering() const { return impl_->chosen; }
std::pair<double, double> SparseLu::measured_orderings() const { return impl_->measured; }

}  // namespace fsi::fluid
