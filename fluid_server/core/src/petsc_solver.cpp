// The PETSc engines (linear_solver.hpp): a KSP on a matrix distributed by rows over the MPI
// ranks. Rank 0 holds the assembled matrix; each solve scatters the rows (pattern once, values
// every solve), the right-hand side and the guess, every rank runs the KSP, and the solution is
// gathered on rank 0. Ranks other than 0 wait in serve() for rank 0's commands (broadcast).
//
// Every decision (rebuild the preconditioner or not) is taken on rank 0 from iteration counts
// and broadcast, so all ranks agree and a run repeats exactly.
#include "petsc_solver.hpp"

#include <fmt/format.h>
#include <mpi.h>
#include <petscksp.h>

#include <Eigen/SparseCore>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <map>
#include <set>
#include <sstream>
#include <stdexcept>
#include <thread>

#include "fsi/common/config.hpp"
#include "fsi/common/log.hpp"
#include "fsi/common/solver_model.hpp"
#include "fsi/fluid/linear_solver.hpp"
#include "mpi_ranks.hpp"

namespace fsi::fluid {
namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

// A PETSc call failed: the call and PETSc's message.
class PetscFailure : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

void check(PetscErrorCode code, const char* call) {
  if (!code) return;
  const char* text = nullptr;
  char* specific = nullptr;
  PetscErrorMessage(code, &text, &specific);
  std::string message = specific && *specific ? specific : (text ? text : "unknown error");
  while (!message.empty() && (message.back() == '\n' || message.back() == ' ')) message.pop_back();
  throw PetscFailure(fmt::format("{} (PETSc error {} in {})", message, static_cast<int>(code), call));
}
#define FSI_PETSC(call) check((call), #call)

enum Command : int { kQuit = 0, kCreate = 1, kSolve = 2, kDestroy = 3 };

int g_size = 1, g_rank = 0;
bool g_serving = false;  // rank 0 of a world of several ranks: the others wait for commands

void finalise() {
  PetscBool up = PETSC_FALSE, down = PETSC_FALSE;
  PetscInitialized(&up);
  PetscFinalized(&down);
  if (!up || down) return;
  if (g_rank == 0 && g_size > 1) {
    // Matches the waiting ranks' MPI_Ibcast (a blocking broadcast would not match it).
    int message[2] = {kQuit, 0};
    MPI_Request request;
    MPI_Ibcast(message, 2, MPI_INT, 0, PETSC_COMM_WORLD, &request);
    MPI_Wait(&request, MPI_STATUS_IGNORE);
  }
  PetscFinalize();
}

void ensure_petsc() {
  PetscBool up = PETSC_FALSE;
  PetscInitialized(&up);
  if (up) return;
  // PETSc reads no command line here: its options come from the scene (and PETSC_OPTIONS).
  FSI_PETSC(PetscInitializeNoArguments());
  PetscPopSignalHandler();  // signals stay with the process (the launcher's SIGTERM, Ctrl-C)
  PetscPushErrorHandler(PetscReturnErrorHandler, nullptr);  // errors come back as codes (check())
  MPI_Comm_size(PETSC_COMM_WORLD, &g_size);
  MPI_Comm_rank(PETSC_COMM_WORLD, &g_rank);
  std::atexit(finalise);
}

int env_int(const char* a, const char* b, int fallback) {
  for (const char* name : {a, b})
    if (const char* v = std::getenv(name)) return std::atoi(v);
  return fallback;
}

void bcast_string(std::string& s) {
  int n = static_cast<int>(s.size());
  MPI_Bcast(&n, 1, MPI_INT, 0, PETSC_COMM_WORLD);
  s.resize(static_cast<std::size_t>(n));
  MPI_Bcast(s.data(), n, MPI_CHAR, 0, PETSC_COMM_WORLD);
}

// Rows [start(r), start(r + 1)) on rank r.
PetscInt row_start(PetscInt n, int size, int r) { return r * (n / size) + std::min<PetscInt>(r, n % size); }

// What rank 0 decides per solve, broadcast to all.
struct Header {
  int n = 0;
  int new_pattern = 0;
  int reuse = 0;
  int has_guess = 0;
  int check_options = 0;
  int max_it = 0;  // > 0: the iteration limit of a solve with a kept preconditioner
  int filled = 0;  // the ranks filled the matrix and rhs (fill); only the guess comes from rank 0
};

}  // namespace

// One KSP on every rank (collective: the same calls in the same order on all ranks).
class PetscSystem {
 public:
  PetscSystem(std::string prefix, std::string options, std::vector<std::string> user_options,
              std::vector<char> pressure)
      : prefix_(std::move(prefix)), user_options_(std::move(user_options)), pressure_(std::move(pressure)) {
    FSI_PETSC(PetscOptionsInsertString(nullptr, options.c_str()));
  }
  ~PetscSystem() { release(); }
  PetscSystem(const PetscSystem&) = delete;
  PetscSystem& operator=(const PetscSystem&) = delete;

  struct Outcome {
    std::string error;  // "" = solved (or rank != 0 after an error: the same error everywhere)
    bool converged = true;
    int iterations = 0;
    int fresh_iterations = 0;  // of the solve with a fresh preconditioner (if it was rebuilt)
    int reason = 0;
    bool rebuilt = false;
    double setup_seconds = 0, solve_seconds = 0;
    std::vector<std::string> unused;  // scene options the solver did not use (check_options)
    std::string description;          // KSP and PC types
  };

  // Rank 0 passes the matrix (CSR by rows), b and the guess; the others nulls.
  Outcome solve(Header h, const Eigen::SparseMatrix<double, Eigen::RowMajor>* A, const Eigen::VectorXd* b,
                const Eigen::VectorXd* guess, Eigen::VectorXd* x) {
    Outcome out;
    MPI_Bcast(&h, sizeof(Header), MPI_BYTE, 0, PETSC_COMM_WORLD);
    try {
      if (h.filled)
        take_guess(h, guess);
      else
        distribute(h, A, b, guess);
      const auto t_setup = Clock::now();
      if (h.new_pattern || !ksp_) build_ksp();
      FSI_PETSC(KSPSetOperators(ksp_, A_, A_));
      FSI_PETSC(KSPSetReusePreconditioner(ksp_, h.reuse ? PETSC_TRUE : PETSC_FALSE));
      FSI_PETSC(KSPSetInitialGuessNonzero(ksp_, h.has_guess && !preonly() ? PETSC_TRUE : PETSC_FALSE));
      FSI_PETSC(KSPSetUp(ksp_));
      out.rebuilt = !h.reuse;
      out.setup_seconds = seconds_since(t_setup);
      PetscReal rtol = 0, abstol = 0, dtol = 0;
      PetscInt max_it = 0;
      FSI_PETSC(KSPGetTolerances(ksp_, &rtol, &abstol, &dtol, &max_it));
      const bool capped = h.reuse && h.max_it > 0 && h.max_it < max_it;
      if (capped) FSI_PETSC(KSPSetTolerances(ksp_, rtol, abstol, dtol, h.max_it));
      run(out);
      if (capped) FSI_PETSC(KSPSetTolerances(ksp_, rtol, abstol, dtol, max_it));
      if (!out.converged && h.reuse) {
        // The kept preconditioner failed (or needed more than the cap): a fresh one, decided
        // alike on every rank from the converged reason they share.
        const auto t_rebuild = Clock::now();
        FSI_PETSC(KSPSetReusePreconditioner(ksp_, PETSC_FALSE));
        FSI_PETSC(KSPSetOperators(ksp_, A_, A_));
        FSI_PETSC(KSPSetUp(ksp_));
        out.setup_seconds += seconds_since(t_rebuild);
        out.rebuilt = true;
        const int before = out.iterations;
        run(out);
        out.fresh_iterations = out.iterations;
        out.iterations += before;
      } else if (out.rebuilt) {
        out.fresh_iterations = out.iterations;
      }
      if (h.check_options) out.unused = unused_options();
      KSPType kt = nullptr;
      PCType pt = nullptr;
      PC pc = nullptr;
      KSPGetType(ksp_, &kt);
      KSPGetPC(ksp_, &pc);
      PCGetType(pc, &pt);
      out.description = fmt::format("KSP {}, PC {}", kt ? kt : "?", pt ? pt : "?");
      gather(x);
    } catch (const PetscFailure& e) {
      out.error = e.what();
      out.converged = false;
      // A system in an unknown state: the next solve builds everything afresh.
      if (ksp_) KSPDestroy(&ksp_);
    }
    return out;
  }

  bool preonly() const {
    if (!ksp_) return false;
    KSPType kt = nullptr;
    KSPGetType(ksp_, &kt);
    return kt && std::string(kt) == KSPPREONLY;
  }

  // Collective (mpi_ranks.hpp, fill_system): A and b from every rank's part, then the
  // constrained rows.
  void fill(const ranks::Part& part, const std::vector<int>& rows, const std::vector<double>& values) {
    if (!A_ || !filled_ || n_ != part.unknowns) create_filled(part);
    const PetscScalar* v = part.values;
    if (part.extra_count > 0) {  // one array: the part's values, then the extra entries'
      const auto own = static_cast<std::size_t>(part.colptr[part.columns]);
      coo_values_.resize(own + static_cast<std::size_t>(part.extra_count));
      std::copy(part.values, part.values + own, coo_values_.begin());
      std::copy(part.extra_values, part.extra_values + part.extra_count, coo_values_.begin() + static_cast<long>(own));
      v = coo_values_.data();
    }
    FSI_PETSC(MatSetValuesCOO(A_, v, INSERT_VALUES));
    FSI_PETSC(VecZeroEntries(b_));
    FSI_PETSC(VecSetValues(b_, part.columns, part.global, part.rhs, ADD_VALUES));
    if (part.extra_rhs_count > 0)
      FSI_PETSC(VecSetValues(b_, part.extra_rhs_count, part.extra_rhs_rows, part.extra_rhs_values, ADD_VALUES));
    FSI_PETSC(VecAssemblyBegin(b_));
    FSI_PETSC(VecAssemblyEnd(b_));
    // Identity rows, rhs the value: MatZeroRows sets b = x on them.
    const auto count = static_cast<PetscInt>(rows.size());
    FSI_PETSC(VecSet(x_, 0.0));
    if (count > 0) FSI_PETSC(VecSetValues(x_, count, rows.data(), values.data(), INSERT_VALUES));
    FSI_PETSC(VecAssemblyBegin(x_));
    FSI_PETSC(VecAssemblyEnd(x_));
    FSI_PETSC(MatZeroRows(A_, count, rows.data(), 1.0, x_, b_));
  }

 private:
  bool filled_ = false;
  std::vector<PetscScalar> coo_values_;  // rank 0 with extra entries: all its values in one array

  // The matrix of a filled system: rows in blocks over the ranks, the pattern and the plan of the
  // assembly (which values go to which rank and position) from every rank's entries once
  // (MatSetPreallocationCOO); the constraints keep the pattern.
  void create_filled(const ranks::Part& part) {
    release();
    n_ = part.unknowns;
    set_layout();
    const PetscInt local = end_ - start_;
    FSI_PETSC(MatCreate(PETSC_COMM_WORLD, &A_));
    FSI_PETSC(MatSetSizes(A_, local, local, n_, n_));
    FSI_PETSC(MatSetType(A_, MATAIJ));
    const auto own = static_cast<std::size_t>(part.colptr[part.columns]);
    std::vector<PetscInt> coo_i(own + static_cast<std::size_t>(part.extra_count)), coo_j(coo_i.size());
    for (int j = 0; j < part.columns; ++j)
      for (int k = part.colptr[j]; k < part.colptr[j + 1]; ++k) {
        coo_i[static_cast<std::size_t>(k)] = part.global[part.rowind[k]];
        coo_j[static_cast<std::size_t>(k)] = part.global[j];
      }
    for (int k = 0; k < part.extra_count; ++k) {
      coo_i[own + static_cast<std::size_t>(k)] = part.extra_rows[k];
      coo_j[own + static_cast<std::size_t>(k)] = part.extra_cols[k];
    }
    FSI_PETSC(MatSetPreallocationCOO(A_, static_cast<PetscCount>(coo_i.size()), coo_i.data(), coo_j.data()));
    FSI_PETSC(MatSetOption(A_, MAT_KEEP_NONZERO_PATTERN, PETSC_TRUE));
    make_vectors();
    filled_ = true;
  }

  // Rank 0's guess into x.
  void take_guess(const Header& h, const Eigen::VectorXd* guess) {
    if (!h.has_guess) return;
    const int local = static_cast<int>(end_ - start_);
    guess_.resize(static_cast<std::size_t>(local));
    MPI_Scatterv(g_rank == 0 ? guess->data() : nullptr, counts_.data(), displs_.data(), MPI_DOUBLE, guess_.data(),
                 local, MPI_DOUBLE, 0, PETSC_COMM_WORLD);
    copy_in(x_, guess_);
  }

  void release() {
    if (ksp_) KSPDestroy(&ksp_);
    if (A_) MatDestroy(&A_);
    if (x_) VecDestroy(&x_);
    if (b_) VecDestroy(&b_);
    if (is_u_) ISDestroy(&is_u_);
    if (is_p_) ISDestroy(&is_p_);
    filled_ = false;
  }

  // Rows [start_, end_) of n_ on this rank; the per-rank counts for scatters and gathers.
  void set_layout() {
    const int size = g_size;
    counts_.assign(static_cast<std::size_t>(size), 0);
    displs_.assign(static_cast<std::size_t>(size), 0);
    for (int r = 0; r < size; ++r) {
      displs_[static_cast<std::size_t>(r)] = static_cast<int>(row_start(n_, size, r));
      counts_[static_cast<std::size_t>(r)] = static_cast<int>(row_start(n_, size, r + 1) - row_start(n_, size, r));
    }
    start_ = row_start(n_, size, g_rank);
    end_ = row_start(n_, size, g_rank + 1);
  }

  // x, b and the velocity / pressure index sets of A's rows.
  void make_vectors() {
    FSI_PETSC(MatCreateVecs(A_, &x_, &b_));
    std::vector<PetscInt> u, p;
    for (PetscInt i = start_; i < end_; ++i) (pressure_[static_cast<std::size_t>(i)] ? p : u).push_back(i);
    FSI_PETSC(ISCreateGeneral(PETSC_COMM_WORLD, static_cast<PetscInt>(u.size()), u.data(), PETSC_COPY_VALUES, &is_u_));
    FSI_PETSC(ISCreateGeneral(PETSC_COMM_WORLD, static_cast<PetscInt>(p.size()), p.data(), PETSC_COPY_VALUES, &is_p_));
  }

  std::string prefix_;
  std::vector<std::string> user_options_;
  std::vector<char> pressure_;
  PetscInt n_ = 0, start_ = 0, end_ = 0;
  std::vector<int> counts_, displs_, nnz_counts_, nnz_displs_;  // per rank: rows, nonzeros
  std::vector<PetscInt> rowptr_, cols_;
  std::vector<PetscScalar> values_, rhs_, guess_;
  Mat A_ = nullptr;
  Vec x_ = nullptr, b_ = nullptr;
  KSP ksp_ = nullptr;
  IS is_u_ = nullptr, is_p_ = nullptr;

  void distribute(const Header& h, const Eigen::SparseMatrix<double, Eigen::RowMajor>* A, const Eigen::VectorXd* b,
                  const Eigen::VectorXd* guess) {
    const int size = g_size, rank = g_rank;
    if (h.new_pattern || !A_ || filled_) {
      n_ = h.n;
      set_layout();
      const int local = static_cast<int>(end_ - start_);
      // Row lengths, then the column indices.
      std::vector<int> lengths;
      if (rank == 0) {
        lengths.resize(static_cast<std::size_t>(n_));
        for (PetscInt i = 0; i < n_; ++i)
          lengths[static_cast<std::size_t>(i)] = A->outerIndexPtr()[i + 1] - A->outerIndexPtr()[i];
        nnz_counts_.assign(static_cast<std::size_t>(size), 0);
        nnz_displs_.assign(static_cast<std::size_t>(size), 0);
        for (int r = 0; r < size; ++r) {
          nnz_displs_[static_cast<std::size_t>(r)] = A->outerIndexPtr()[row_start(n_, size, r)];
          nnz_counts_[static_cast<std::size_t>(r)] =
              A->outerIndexPtr()[row_start(n_, size, r + 1)] - A->outerIndexPtr()[row_start(n_, size, r)];
        }
      }
      std::vector<int> my_lengths(static_cast<std::size_t>(local));
      MPI_Scatterv(lengths.data(), counts_.data(), displs_.data(), MPI_INT, my_lengths.data(), local, MPI_INT, 0,
                   PETSC_COMM_WORLD);
      rowptr_.assign(static_cast<std::size_t>(local) + 1, 0);
      for (int i = 0; i < local; ++i)
        rowptr_[static_cast<std::size_t>(i) + 1] =
            rowptr_[static_cast<std::size_t>(i)] + my_lengths[static_cast<std::size_t>(i)];
      const int my_nnz = static_cast<int>(rowptr_.back());
      cols_.resize(static_cast<std::size_t>(my_nnz));
      static_assert(sizeof(PetscInt) == sizeof(int), "PETSc with 32-bit indices");
      MPI_Scatterv(rank == 0 ? A->innerIndexPtr() : nullptr, nnz_counts_.data(), nnz_displs_.data(), MPI_INT,
                   cols_.data(), my_nnz, MPI_INT, 0, PETSC_COMM_WORLD);
      values_.resize(static_cast<std::size_t>(my_nnz));
      rhs_.resize(static_cast<std::size_t>(local));
      guess_.resize(static_cast<std::size_t>(local));
    }
    const int local = static_cast<int>(end_ - start_);
    MPI_Scatterv(rank == 0 ? A->valuePtr() : nullptr, nnz_counts_.data(), nnz_displs_.data(), MPI_DOUBLE,
                 values_.data(), static_cast<int>(values_.size()), MPI_DOUBLE, 0, PETSC_COMM_WORLD);
    MPI_Scatterv(rank == 0 ? b->data() : nullptr, counts_.data(), displs_.data(), MPI_DOUBLE, rhs_.data(), local,
                 MPI_DOUBLE, 0, PETSC_COMM_WORLD);
    if (h.has_guess)
      MPI_Scatterv(rank == 0 ? guess->data() : nullptr, counts_.data(), displs_.data(), MPI_DOUBLE, guess_.data(),
                   local, MPI_DOUBLE, 0, PETSC_COMM_WORLD);

    if (h.new_pattern || !A_ || filled_) {
      release();
      FSI_PETSC(MatCreate(PETSC_COMM_WORLD, &A_));
      FSI_PETSC(MatSetSizes(A_, local, local, n_, n_));
      FSI_PETSC(MatSetType(A_, MATAIJ));
      FSI_PETSC(MatSeqAIJSetPreallocationCSR(A_, rowptr_.data(), cols_.data(), values_.data()));
      FSI_PETSC(MatMPIAIJSetPreallocationCSR(A_, rowptr_.data(), cols_.data(), values_.data()));
      make_vectors();
    } else {
      for (int i = 0; i < local; ++i) {
        const PetscInt row = start_ + i;
        const auto k = static_cast<std::size_t>(rowptr_[static_cast<std::size_t>(i)]);
        FSI_PETSC(MatSetValues(A_, 1, &row,
                               rowptr_[static_cast<std::size_t>(i) + 1] - rowptr_[static_cast<std::size_t>(i)],
                               &cols_[k], &values_[k], INSERT_VALUES));
      }
      FSI_PETSC(MatAssemblyBegin(A_, MAT_FINAL_ASSEMBLY));
      FSI_PETSC(MatAssemblyEnd(A_, MAT_FINAL_ASSEMBLY));
    }
    copy_in(b_, rhs_);
    if (h.has_guess) copy_in(x_, guess_);
  }

  static void copy_in(Vec v, const std::vector<PetscScalar>& values) {
    PetscScalar* a = nullptr;
    FSI_PETSC(VecGetArray(v, &a));
    std::copy(values.begin(), values.end(), a);
    FSI_PETSC(VecRestoreArray(v, &a));
  }

  void build_ksp() {
    if (ksp_) KSPDestroy(&ksp_);
    FSI_PETSC(KSPCreate(PETSC_COMM_WORLD, &ksp_));
    FSI_PETSC(KSPSetOptionsPrefix(ksp_, prefix_.c_str()));
    FSI_PETSC(KSPSetOperators(ksp_, A_, A_));
    FSI_PETSC(KSPSetFromOptions(ksp_));
    PC pc = nullptr;
    FSI_PETSC(KSPGetPC(ksp_, &pc));
    // The velocity / pressure split (no-ops unless the PC is fieldsplit).
    FSI_PETSC(PCFieldSplitSetIS(pc, "u", is_u_));
    FSI_PETSC(PCFieldSplitSetIS(pc, "p", is_p_));
  }

  void run(Outcome& out) {
    const auto t = Clock::now();
    FSI_PETSC(KSPSolve(ksp_, b_, x_));
    out.solve_seconds += seconds_since(t);
    KSPConvergedReason reason;
    PetscInt its = 0;
    FSI_PETSC(KSPGetConvergedReason(ksp_, &reason));
    FSI_PETSC(KSPGetIterationNumber(ksp_, &its));
    out.reason = static_cast<int>(reason);
    out.iterations = static_cast<int>(its);
    out.converged = reason > 0;
  }

  void gather(Eigen::VectorXd* x) {
    const PetscScalar* a = nullptr;
    FSI_PETSC(VecGetArrayRead(x_, &a));
    if (g_rank == 0) x->resize(n_);
    MPI_Gatherv(a, static_cast<int>(end_ - start_), MPI_DOUBLE, g_rank == 0 ? x->data() : nullptr, counts_.data(),
                displs_.data(), MPI_DOUBLE, 0, PETSC_COMM_WORLD);
    FSI_PETSC(VecRestoreArrayRead(x_, &a));
  }

  // The scene's options (names without '-') that no PETSc object of this solver has read.
  std::vector<std::string> unused_options() const {
    PetscInt count = 0;
    char **names = nullptr, **values = nullptr;
    FSI_PETSC(PetscOptionsLeftGet(nullptr, &count, &names, &values));
    std::vector<std::string> unused;
    for (PetscInt i = 0; i < count; ++i) {
      std::string name = names[i];
      if (!name.empty() && name[0] == '-') name.erase(0, 1);
      if (name.rfind(prefix_, 0) != 0) continue;
      name.erase(0, prefix_.size());
      if (std::find(user_options_.begin(), user_options_.end(), name) != user_options_.end()) unused.push_back(name);
    }
    PetscOptionsLeftRestore(nullptr, &count, &names, &values);
    return unused;
  }
};

namespace {

// Option names of an options string ("-ksp_rtol 1e-10 -ksp_monitor": ksp_rtol, ksp_monitor).
std::vector<std::string> option_names(const std::string& options) {
  std::istringstream in(options);
  std::vector<std::string> names;
  for (std::string token; in >> token;)
    if (token.size() > 1 && token[0] == '-' && !std::isdigit(static_cast<unsigned char>(token[1])) && token[1] != '.')
      names.push_back(token.substr(1));
  return names;
}

// `options` with every option name given the prefix.
std::string prefixed(const std::string& options, const std::string& prefix) {
  std::istringstream in(options);
  std::string out;
  for (std::string token; in >> token;) {
    if (!out.empty()) out += ' ';
    if (token.size() > 1 && token[0] == '-' && !std::isdigit(static_cast<unsigned char>(token[1])) && token[1] != '.')
      out += "-" + prefix + token.substr(1);
    else
      out += token;
  }
  return out;
}

// Rank > 0: the systems rank 0 made, by id.
std::map<int, std::unique_ptr<PetscSystem>>& served() {
  static std::map<int, std::unique_ptr<PetscSystem>> systems;
  return systems;
}

// Rank 0: its own systems, by id (the PetscSolvers own them).
std::map<int, PetscSystem*>& own() {
  static std::map<int, PetscSystem*> systems;
  return systems;
}

PetscSystem& system_of(int id) {
  if (g_rank == 0) {
    if (const auto it = own().find(id); it != own().end()) return *it->second;
  } else if (const auto it = served().find(id); it != served().end()) {
    return *it->second;
  }
  std::fprintf(stderr, "fluid_server rank %d: an unknown linear system %d\n", g_rank, id);
  MPI_Abort(PETSC_COMM_WORLD, 3);
  std::abort();
}

struct CreateMessage {
  int id = 0;
  std::string prefix, options;
  std::vector<std::string> user;
  std::vector<char> pressure;
};

// Collective on all ranks: rank 0's message reaches every rank.
void bcast_create(CreateMessage& m) {
  MPI_Bcast(&m.id, 1, MPI_INT, 0, PETSC_COMM_WORLD);
  bcast_string(m.prefix);
  bcast_string(m.options);
  int count = static_cast<int>(m.user.size());
  MPI_Bcast(&count, 1, MPI_INT, 0, PETSC_COMM_WORLD);
  m.user.resize(static_cast<std::size_t>(count));
  for (auto& u : m.user) bcast_string(u);
  int n = static_cast<int>(m.pressure.size());
  MPI_Bcast(&n, 1, MPI_INT, 0, PETSC_COMM_WORLD);
  m.pressure.resize(static_cast<std::size_t>(n));
  MPI_Bcast(m.pressure.data(), n, MPI_CHAR, 0, PETSC_COMM_WORLD);
}

void send_command(int command, int id) {
  if (g_size <= 1) return;
  int message[2] = {command, id};
  MPI_Request request;  // nonblocking, as the waiting ranks' MPI_Ibcast it must match
  MPI_Ibcast(message, 2, MPI_INT, 0, PETSC_COMM_WORLD, &request);
  MPI_Wait(&request, MPI_STATUS_IGNORE);
}

// Rank > 0: waits for rank 0's next command without spinning a core (rank 0 may be assembling).
void receive_command(int& command, int& id) {
  int message[2] = {0, 0};
  MPI_Request request;
  MPI_Ibcast(message, 2, MPI_INT, 0, PETSC_COMM_WORLD, &request);
  int done = 0;
  auto pause = std::chrono::microseconds(50);
  while (MPI_Test(&request, &done, MPI_STATUS_IGNORE) == MPI_SUCCESS && !done) {
    std::this_thread::sleep_for(pause);
    pause = std::min(pause * 2, std::chrono::microseconds(2000));
  }
  command = message[0];
  id = message[1];
}

// Ranks > 0: the handlers of the commands other parts of the fluid registered (mpi_ranks.hpp).
std::map<int, ranks::Handler>& handlers() {
  static std::map<int, ranks::Handler> table;
  return table;
}

int serve() {
  for (;;) {
    int command = kQuit, id = 0;
    receive_command(command, id);
    if (command == kQuit) break;
    if (command == kCreate) {
      CreateMessage m;
      bcast_create(m);
      try {
        served()[m.id] = std::make_unique<PetscSystem>(m.prefix, m.options, m.user, m.pressure);
      } catch (const PetscFailure&) {  // rank 0 reports the same error
      }
    } else if (command == kSolve) {
      auto it = served().find(id);
      if (it == served().end()) {
        std::fprintf(stderr, "fluid_server rank %d: solve of an unknown system %d\n", g_rank, id);
        MPI_Abort(PETSC_COMM_WORLD, 3);
      }
      it->second->solve(Header{}, nullptr, nullptr, nullptr, nullptr);
    } else if (command == kDestroy) {
      served().erase(id);
    } else if (const auto h = handlers().find(command); h != handlers().end()) {
      h->second(command, id);
    } else {
      std::fprintf(stderr, "fluid_server rank %d: unknown command %d from rank 0\n", g_rank, command);
      MPI_Abort(PETSC_COMM_WORLD, 3);
    }
  }
  served().clear();
  PetscFinalize();
  return 0;
}

std::string engine_name(LinearEngine e) { return e == LinearEngine::Mumps ? "mumps" : "petsc"; }

}  // namespace

std::string petsc_default_options(LinearEngine engine) {
  if (engine == LinearEngine::Mumps) return "-ksp_type preonly -pc_type lu -pc_factor_mat_solver_type mumps";
  return "-ksp_type gmres -ksp_pc_side right -ksp_gmres_restart 200 -ksp_rtol 1e-10 -ksp_max_it 1000 "
         "-pc_type fieldsplit -pc_fieldsplit_type schur -pc_fieldsplit_schur_fact_type lower "
         "-pc_fieldsplit_schur_precondition selfp "
         "-fieldsplit_u_ksp_type preonly -fieldsplit_u_pc_type bjacobi -fieldsplit_u_sub_pc_type ilu "
         "-fieldsplit_p_ksp_type preonly -fieldsplit_p_pc_type hypre -fieldsplit_p_pc_hypre_type boomeramg";
}

struct PetscSolver::Impl {
  FlowParameters params;
  int id = 0;
  std::string prefix;
  std::unique_ptr<PetscSystem> system;
  bool options_checked = false;
  bool have_pattern = false;
  // The pattern of the distributed matrix (a new one rebuilds it).
  Eigen::Index rows = -1, nonzeros = -1;
  // Preconditioner reuse: iterations of the first solve with the current preconditioner.
  bool have_pc = false;
  int pc_iterations = 0;
  double time_coefficient = 0;
  bool logged = false;
};

PetscSolver::PetscSolver(const FlowParameters& params, std::vector<char> pressure) : impl_(std::make_unique<Impl>()) {
  ensure_petsc();
  auto& s = *impl_;
  s.params = params;
  static int next_id = 0;
  s.id = next_id++;
  s.prefix = fmt::format("fsi{}_", s.id);
  const std::string user = params.petsc_options;
  CreateMessage m{s.id, s.prefix, prefixed(petsc_default_options(params.engine) + " " + user, s.prefix),
                  option_names(user), std::move(pressure)};
  send_command(kCreate, s.id);
  if (g_size > 1) bcast_create(m);
  try {
    s.system = std::make_unique<PetscSystem>(m.prefix, m.options, m.user, m.pressure);
  } catch (const PetscFailure& e) {
    throw std::invalid_argument(fmt::format("fluid.linear_solver.petsc_options: {}", e.what()));
  }
  own()[s.id] = s.system.get();
}

PetscSolver::~PetscSolver() {
  if (!impl_) return;
  PetscBool down = PETSC_FALSE;
  PetscFinalized(&down);
  if (down) {
    own().erase(impl_->id);
    (void)impl_->system.release();  // PETSc is gone with its objects
    return;
  }
  send_command(kDestroy, impl_->id);  // first: destroying the objects is collective
  own().erase(impl_->id);
  impl_->system.reset();
}

Eigen::VectorXd PetscSolver::solve(const Eigen::SparseMatrix<double>& A, const Eigen::VectorXd& b,
                                   const Eigen::VectorXd& guess, StepReport& report, const std::string& where,
                                   double time_coefficient) {
  const Eigen::SparseMatrix<double, Eigen::RowMajor> rows = A;
  return run(A.rows(), A.nonZeros(), &rows, &b, guess, report, where, time_coefficient);
}

Eigen::VectorXd PetscSolver::solve_filled(int unknowns, const Eigen::VectorXd& guess, StepReport& report,
                                          const std::string& where, double time_coefficient) {
  return run(unknowns, -1, nullptr, nullptr, guess, report, where, time_coefficient);
}

int PetscSolver::partition_id() const { return g_size > 1 ? impl_->id : -1; }

// `rows` null: the ranks filled the system (fill_system); `nonzeros` -1 then (the pattern is the
// filled matrix's, new when the number of unknowns changes).
Eigen::VectorXd PetscSolver::run(Eigen::Index unknowns, Eigen::Index nonzeros,
                                 const Eigen::SparseMatrix<double, Eigen::RowMajor>* rows, const Eigen::VectorXd* b,
                                 const Eigen::VectorXd& guess, StepReport& report, const std::string& where,
                                 double time_coefficient) {
  auto& s = *impl_;
  Header h;
  h.n = static_cast<int>(unknowns);
  h.filled = rows == nullptr;
  h.new_pattern = !s.have_pattern || unknowns != s.rows || nonzeros != s.nonzeros;
  h.has_guess = guess.size() == unknowns;
  h.check_options = !s.options_checked;
  if (h.new_pattern || time_coefficient != s.time_coefficient) s.have_pc = false;
  h.reuse = s.params.petsc_reuse_preconditioner && s.have_pc && !s.system->preonly();
  // A kept preconditioner gets as many iterations as the rebuild rule allows; beyond, a fresh one.
  if (h.reuse) h.max_it = static_cast<int>(std::ceil(s.params.petsc_rebuild_factor * s.pc_iterations)) + 5;
  Eigen::VectorXd x;
  send_command(kSolve, s.id);
  const auto outcome = s.system->solve(h, rows, b, h.has_guess ? &guess : nullptr, &x);
  if (!outcome.error.empty()) {
    s.have_pattern = false;
    s.have_pc = false;
    throw SolverError(
        fmt::format("{}: the PETSc solve ({}) failed: {}", where, engine_name(s.params.engine), outcome.error));
  }
  s.have_pattern = true;
  s.rows = unknowns;
  s.nonzeros = nonzeros;
  s.time_coefficient = time_coefficient;
  if (h.check_options) {
    s.options_checked = true;
    if (!outcome.unused.empty()) {
      std::string list;
      for (const auto& u : outcome.unused) list += (list.empty() ? "-" : ", -") + u;
      throw ConfigError(fmt::format(
          "fluid.linear_solver.petsc_options: {} {} not used by the PETSc solver (unknown option, or one the "
          "chosen KSP/PC does not take; engine {}, {})",
          list, outcome.unused.size() == 1 ? "was" : "were", engine_name(s.params.engine), outcome.description));
    }
  }
  if (!s.logged) {
    s.logged = true;
    fsi::logger("fluid")->info("linear solver: PETSc ({}) on {} rank(s), {}, {} unknowns; first solve {} iterations",
                               engine_name(s.params.engine), g_size, outcome.description, unknowns, outcome.iterations);
  }
  report.krylov_iterations += outcome.iterations;
  report.factor_seconds += outcome.setup_seconds;
  report.solve_seconds += outcome.solve_seconds;
  if (outcome.rebuilt) {
    ++report.factorisations;
    s.pc_iterations = outcome.fresh_iterations;
    s.have_pc = true;
  }
  if (!outcome.converged)
    throw SolverError(fmt::format("{}: the PETSc solve ({}, {}) did not converge: {} after {} iterations", where,
                                  engine_name(s.params.engine), outcome.description,
                                  KSPConvergedReasons[outcome.reason], outcome.iterations));
  // Rebuild next time once the kept preconditioner needs clearly more iterations than fresh.
  if (!outcome.rebuilt && outcome.iterations > s.params.petsc_rebuild_factor * s.pc_iterations + 5) s.have_pc = false;
  if (!x.allFinite()) throw SolverError(fmt::format("{}: the solution is not finite", where));
  return x;
}

void PetscSolver::discard_factors() { impl_->have_pc = false; }
void PetscSolver::save_state(StateArchive&, const std::string&) const {}
void PetscSolver::load_state(const StateArchive&, const std::string&) { discard_factors(); }

namespace ranks {

bool on_command(int command, Handler handler) {
  handlers()[command] = handler;
  return true;
}

bool up() {
  PetscBool initialised = PETSC_FALSE, finalised = PETSC_FALSE;
  PetscInitialized(&initialised);
  PetscFinalized(&finalised);
  return initialised && !finalised;
}

int size() { return up() ? g_size : 1; }
int rank() { return up() ? g_rank : 0; }

bool command(int command, int id) {
  if (!up() || g_size <= 1 || g_rank != 0) return false;
  send_command(command, id);
  return true;
}

namespace {
// MPI counts are int: long arrays go in pieces.
constexpr std::size_t kPiece = std::size_t{1} << 30;
}  // namespace

void broadcast(double* data, std::size_t count) {
  for (std::size_t k = 0; k < count; k += kPiece)
    MPI_Bcast(data + k, static_cast<int>(std::min(kPiece, count - k)), MPI_DOUBLE, 0, PETSC_COMM_WORLD);
}

void broadcast(int* data, std::size_t count) {
  for (std::size_t k = 0; k < count; k += kPiece)
    MPI_Bcast(data + k, static_cast<int>(std::min(kPiece, count - k)), MPI_INT, 0, PETSC_COMM_WORLD);
}

void broadcast(std::string& text) { bcast_string(text); }

void sum_to_root(double* data, std::size_t count) {
  for (std::size_t k = 0; k < count; k += kPiece) {
    const int n = static_cast<int>(std::min(kPiece, count - k));
    if (g_rank == 0)
      MPI_Reduce(MPI_IN_PLACE, data + k, n, MPI_DOUBLE, MPI_SUM, 0, PETSC_COMM_WORLD);
    else
      MPI_Reduce(data + k, nullptr, n, MPI_DOUBLE, MPI_SUM, 0, PETSC_COMM_WORLD);
  }
}

void gather_to_root(const double* mine, int count, double* all) {
  MPI_Gather(mine, count, MPI_DOUBLE, all, count, MPI_DOUBLE, 0, PETSC_COMM_WORLD);
}

void fill_system(int id, const Part& part, const std::vector<int>& rows, const std::vector<double>& values) {
  static_assert(sizeof(PetscInt) == sizeof(int), "PETSc with 32-bit indices");
  try {
    system_of(id).fill(part, rows, values);
  } catch (const PetscFailure& e) {
    throw std::runtime_error(e.what());
  }
}

}  // namespace ranks

int petsc_start_mpi_ranks() {
  if (env_int("OMPI_COMM_WORLD_SIZE", "PMI_SIZE", 1) <= 1) return -1;
  ensure_petsc();
  if (g_rank == 0) {
    g_serving = true;
    return -1;
  }
  return serve();
}

}  // namespace fsi::fluid
