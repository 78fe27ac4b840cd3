// linear_solver_bench: UMFPACK (the project's direct solve) against PETSc Krylov solvers with a
// Schur-complement block preconditioner on a representative Taylor-Hood P2/P1 time-step matrix
// of DFG 2D-2 (Re 100, rho 1, mu 1e-3, BDF2 semi-implicit, dt 0.002).
//
// Built only when PETSc is found (pkg-config PETSc / petsc; Debian: apt-get install libpetsc-real-dev).
// Run single-threaded, one process, no mpirun (results: bench/fluid/linear_solver_bench.md):
//   OPENBLAS_NUM_THREADS=1 OMP_NUM_THREADS=1 build/bin/linear_solver_bench --h 0.05 --hc 0.006 --steps 50
// Options: --h H --hc HC --steps K --dt DT --reps R --lags 1,5,10 --ramp T (inflow ramp time;
// default 0 = impulsive start) --configs name,name,... (default: all) --lag-config NAME (the
// configuration whose preconditioner is built on the older matrices) --zero-guess --cache DIR
// --rtol R (PETSc, default 1e-8) --bicgstab-tol T (default 1e-10, the project's krylov_tolerance).
// Anything starting with a single '-' is left to PETSc (e.g. -p2_ksp_view, -options_left).
//
// Every repetition runs every solver once, interleaved, in this process (so that the load of
// other processes on the machine hits all of them alike); the tables give medians.
#include <petscksp.h>

#include <Eigen/IterativeLinearSolvers>
#include <Eigen/SparseCore>
#include <Eigen/UmfPackSupport>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <map>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "fsi/common/gmsh_reader.hpp"
#include "fsi/fluid/navier_stokes_fluid.hpp"
#include "fsi/fluid/taylor_hood_solver.hpp"

namespace {

using SpMat = Eigen::SparseMatrix<double>;
using Clock = std::chrono::steady_clock;
double ms_since(Clock::time_point t0) { return 1e3 * std::chrono::duration<double>(Clock::now() - t0).count(); }

#define PCHK(expr)                                                                                           \
  do {                                                                                                       \
    const PetscErrorCode ierr_ = (expr);                                                                     \
    if (ierr_) throw std::runtime_error(std::string("PETSc error ") + std::to_string(ierr_) + " in " #expr); \
  } while (0)

static_assert(sizeof(PetscInt) == sizeof(SpMat::StorageIndex), "PETSc with 32-bit indices expected");
static_assert(sizeof(PetscScalar) == sizeof(double), "real double PETSc expected");

double median(std::vector<double> v) {
  if (v.empty()) return NAN;
  std::sort(v.begin(), v.end());
  const std::size_t m = v.size() / 2;
  return v.size() % 2 ? v[m] : 0.5 * (v[m - 1] + v[m]);
}

double residual(const SpMat& A, const Eigen::VectorXd& x, const Eigen::VectorXd& b) {
  return (A * x - b).norm() / b.norm();
}

// --- UMFPACK as the project uses it (sparse_lu.cpp): AMD, symmetric strategy, no refinement. ---
using Umf = Eigen::UmfPackLU<SpMat>;
void configure(Umf& lu) {
  lu.umfpackControl()(UMFPACK_ORDERING) = UMFPACK_ORDERING_AMD;
  lu.umfpackControl()(UMFPACK_STRATEGY) = UMFPACK_STRATEGY_SYMMETRIC;
  lu.umfpackControl()(UMFPACK_IRSTEP) = 0;
}

// The factors of an earlier matrix as a preconditioner (as sparse_lu.cpp's FrozenLuPreconditioner).
class FrozenLu {
 public:
  void set(const Umf* lu) { lu_ = lu; }
  template <class M>
  FrozenLu& analyzePattern(const M&) {
    return *this;
  }
  template <class M>
  FrozenLu& factorize(const M&) {
    return *this;
  }
  template <class M>
  FrozenLu& compute(const M&) {
    return *this;
  }
  template <class R>
  Eigen::VectorXd solve(const Eigen::MatrixBase<R>& b) const {
    return lu_->solve(b);
  }
  Eigen::ComputationInfo info() const { return Eigen::Success; }

 private:
  const Umf* lu_ = nullptr;
};

// --- PETSc helpers ---
struct PetscMatrix {
  Mat mat = nullptr;
  Eigen::SparseMatrix<double, Eigen::RowMajor> csr;  // same pattern (sorted columns)
  explicit PetscMatrix(const SpMat& A) : csr(A) {
    csr.makeCompressed();
    PCHK(MatCreate(PETSC_COMM_SELF, &mat));
    PCHK(MatSetSizes(mat, csr.rows(), csr.cols(), csr.rows(), csr.cols()));
    PCHK(MatSetType(mat, MATSEQAIJ));
    PCHK(MatSeqAIJSetPreallocationCSR(mat, csr.outerIndexPtr(), csr.innerIndexPtr(), csr.valuePtr()));
  }
  // A new matrix of the same pattern, as a time step would give it: copy the values in place
  // (the object state changes, so the next KSPSetUp rebuilds the preconditioner).
  void update_values() {
    PetscScalar* v = nullptr;
    PCHK(MatSeqAIJGetArray(mat, &v));
    std::memcpy(v, csr.valuePtr(), sizeof(double) * static_cast<std::size_t>(csr.nonZeros()));
    PCHK(MatSeqAIJRestoreArray(mat, &v));
  }
  ~PetscMatrix() { MatDestroy(&mat); }
  PetscMatrix(const PetscMatrix&) = delete;
  PetscMatrix& operator=(const PetscMatrix&) = delete;
};

void to_vec(const Eigen::VectorXd& x, Vec v) {
  PetscScalar* a = nullptr;
  PCHK(VecGetArray(v, &a));
  std::copy(x.data(), x.data() + x.size(), a);
  PCHK(VecRestoreArray(v, &a));
}
Eigen::VectorXd from_vec(Vec v) {
  PetscInt n = 0;
  PCHK(VecGetLocalSize(v, &n));
  const PetscScalar* a = nullptr;
  PCHK(VecGetArrayRead(v, &a));
  Eigen::VectorXd x = Eigen::Map<const Eigen::VectorXd>(a, n);
  PCHK(VecRestoreArrayRead(v, &a));
  return x;
}

// Cahouet-Chabard-like Schur preconditioner as a PCSHELL on the Schur split:
//   S^-1 ~ AMG(S_p)^-1 + s mu M_p,lumped^-1,   S_p = -A10 diag(A00)^-1 A01 (PETSc's selfp),
// s the sign of S_p's diagonal (so the two parts add up with the same sign).
struct CahouetChabard {
  PC amg = nullptr;
  Vec mass_inverse = nullptr;  // mu / lumped pressure mass, signed
  Vec work = nullptr;
  Eigen::VectorXd lumped_mass;
  double mu = 1e-3;
  ~CahouetChabard() {
    if (amg) PCDestroy(&amg);
    if (mass_inverse) VecDestroy(&mass_inverse);
    if (work) VecDestroy(&work);
  }
};

PetscErrorCode cc_setup(PC pc) {
  void* ctx = nullptr;
  PetscCall(PCShellGetContext(pc, &ctx));
  auto* cc = static_cast<CahouetChabard*>(ctx);
  Mat Amat, Pmat;
  PetscCall(PCGetOperators(pc, &Amat, &Pmat));
  if (!cc->amg) {
    PetscCall(PCCreate(PETSC_COMM_SELF, &cc->amg));
    PetscCall(PCSetType(cc->amg, PCHYPRE));
    PetscCall(PCHYPRESetType(cc->amg, "boomeramg"));
    PetscCall(PCSetOptionsPrefix(cc->amg, "cc_amg_"));
    PetscCall(PCSetFromOptions(cc->amg));
  }
  PetscCall(PCSetOperators(cc->amg, Pmat, Pmat));
  PetscCall(PCSetUp(cc->amg));
  if (!cc->mass_inverse) {
    PetscCall(MatCreateVecs(Pmat, &cc->mass_inverse, &cc->work));
  }
  PetscCall(MatGetDiagonal(Pmat, cc->work));
  PetscScalar diagonal_sum = 0;
  PetscCall(VecSum(cc->work, &diagonal_sum));
  const double sign = diagonal_sum < 0 ? -1.0 : 1.0;
  PetscScalar* a = nullptr;
  PetscCall(VecGetArray(cc->mass_inverse, &a));
  for (Eigen::Index i = 0; i < cc->lumped_mass.size(); ++i) a[i] = sign * cc->mu / cc->lumped_mass(i);
  PetscCall(VecRestoreArray(cc->mass_inverse, &a));
  return 0;
}

PetscErrorCode cc_apply(PC pc, Vec x, Vec y) {
  void* ctx = nullptr;
  PetscCall(PCShellGetContext(pc, &ctx));
  auto* cc = static_cast<CahouetChabard*>(ctx);
  PetscCall(PCApply(cc->amg, x, y));
  PetscCall(VecPointwiseMult(cc->work, cc->mass_inverse, x));
  PetscCall(VecAXPY(y, 1.0, cc->work));
  return 0;
}

struct PetscConfig {
  std::string name, description, options;  // options without prefix; the prefix is name + "_"
  bool cahouet_chabard = false;
};

std::string prefixed(const std::string& prefix, const std::string& options) {
  // Prefix every "-key" token.
  std::string out;
  std::size_t i = 0;
  while (i < options.size()) {
    while (i < options.size() && options[i] == ' ') ++i;
    if (i >= options.size()) break;
    std::size_t j = options.find(' ', i);
    if (j == std::string::npos) j = options.size();
    std::string token = options.substr(i, j - i);
    if (token.size() > 1 && token[0] == '-' && !std::isdigit(static_cast<unsigned char>(token[1])))
      token = "-" + prefix + token.substr(1);
    out += token + " ";
    i = j;
  }
  return out;
}

std::string fmt_double(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", v);
  return buf;
}

std::vector<PetscConfig> petsc_configs(double rtol) {
  const std::string outer = "-ksp_type fgmres -ksp_gmres_restart 200 -ksp_rtol " + fmt_double(rtol) +
                            " -ksp_atol 1e-50 -ksp_max_it 1000 "
                            "-pc_type fieldsplit -pc_fieldsplit_type schur -pc_fieldsplit_schur_precondition selfp ";
  const std::string u_amg =
      "-fieldsplit_u_ksp_type preonly -fieldsplit_u_pc_type hypre -fieldsplit_u_pc_hypre_type boomeramg ";
  const std::string p_amg =
      "-fieldsplit_p_ksp_type preonly -fieldsplit_p_pc_type hypre -fieldsplit_p_pc_hypre_type boomeramg ";
  const std::string hmis =
      "-pc_hypre_boomeramg_coarsen_type HMIS -pc_hypre_boomeramg_interp_type ext+i "
      "-pc_hypre_boomeramg_P_max 4 ";
  return {
      {"full_amg", "FGMRES, Schur full, u: 1 AMG V-cycle, S(selfp): 1 AMG V-cycle",
       outer + "-pc_fieldsplit_schur_fact_type full " + u_amg + p_amg},
      {"upper_amg", "FGMRES, Schur upper, u: 1 AMG V-cycle, S(selfp): 1 AMG V-cycle",
       outer + "-pc_fieldsplit_schur_fact_type upper " + u_amg + p_amg},
      {"upper_amg2", "FGMRES, Schur upper, u: 2 AMG V-cycles (Richardson), S(selfp): 1 AMG V-cycle",
       outer + "-pc_fieldsplit_schur_fact_type upper " + u_amg +
           "-fieldsplit_u_ksp_type richardson -fieldsplit_u_ksp_max_it 2 -fieldsplit_u_ksp_norm_type none " + p_amg},
      {"upper_hmis", "FGMRES, Schur upper, u and S(selfp): 1 AMG V-cycle, HMIS coarsening + ext+i interpolation",
       outer + "-pc_fieldsplit_schur_fact_type upper " + u_amg + prefixed("fieldsplit_u_", hmis) + p_amg +
           prefixed("fieldsplit_p_", hmis)},
      {"upper_ilu", "FGMRES, Schur upper, u: ILU(0), S(selfp): 1 AMG V-cycle",
       outer + "-pc_fieldsplit_schur_fact_type upper -fieldsplit_u_ksp_type preonly -fieldsplit_u_pc_type ilu " +
           p_amg},
      {"upper_sor", "FGMRES, Schur upper, u: 1 SSOR sweep, S(selfp): 1 AMG V-cycle",
       outer +
           "-pc_fieldsplit_schur_fact_type upper -fieldsplit_u_ksp_type preonly -fieldsplit_u_pc_type sor "
           "-fieldsplit_u_pc_sor_symmetric " +
           p_amg},
      {"full_ilu", "FGMRES, Schur full, u: ILU(0), S(selfp): 1 AMG V-cycle",
       outer + "-pc_fieldsplit_schur_fact_type full -fieldsplit_u_ksp_type preonly -fieldsplit_u_pc_type ilu " + p_amg},
      {"upper_asm", "FGMRES, Schur upper, u: ASM 8 blocks overlap 1 + ILU(0), S(selfp): 1 AMG V-cycle",
       outer +
           "-pc_fieldsplit_schur_fact_type upper -fieldsplit_u_ksp_type preonly -fieldsplit_u_pc_type asm "
           "-fieldsplit_u_pc_asm_blocks 8 -fieldsplit_u_pc_asm_overlap 1 -fieldsplit_u_sub_pc_type ilu " +
           p_amg},
      {"upper_amg_cc", "FGMRES, Schur upper, u: 1 AMG V-cycle, S: AMG(selfp)^-1 + mu M_p^-1 (Cahouet-Chabard, lumped)",
       outer + "-pc_fieldsplit_schur_fact_type upper " + u_amg +
           "-fieldsplit_p_ksp_type preonly -fieldsplit_p_pc_type shell ",
       true},
  };
}

// One PETSc solver: a KSP with its prefix, the index sets, and (for the lagged variant) a
// preconditioning matrix different from the operator.
struct PetscSolver {
  PetscConfig config;
  KSP ksp = nullptr;
  IS is_u = nullptr, is_p = nullptr;
  std::unique_ptr<CahouetChabard> cc;
  bool shell_ready = false;

  PetscSolver(const PetscConfig& c, int n_velocity, int n_pressure, const Eigen::VectorXd& lumped_mass, double mu)
      : config(c) {
    const std::string prefix = c.name + "_";
    PCHK(PetscOptionsInsertString(nullptr, prefixed(prefix, c.options).c_str()));
    PCHK(KSPCreate(PETSC_COMM_SELF, &ksp));
    PCHK(KSPSetOptionsPrefix(ksp, prefix.c_str()));
    PCHK(ISCreateStride(PETSC_COMM_SELF, n_velocity, 0, 1, &is_u));
    PCHK(ISCreateStride(PETSC_COMM_SELF, n_pressure, n_velocity, 1, &is_p));
    if (c.cahouet_chabard) {
      cc = std::make_unique<CahouetChabard>();
      cc->lumped_mass = lumped_mass;
      cc->mu = mu;
    }
  }
  ~PetscSolver() {
    KSPDestroy(&ksp);
    ISDestroy(&is_u);
    ISDestroy(&is_p);
  }
  PetscSolver(const PetscSolver&) = delete;
  PetscSolver& operator=(const PetscSolver&) = delete;

  // Operators, set-up of the preconditioner (forced down to the blocks so that the set-up
  // time holds all of it); returns ms.
  double setup(Mat A, Mat P) {
    const auto t0 = Clock::now();
    PCHK(KSPSetOperators(ksp, A, P));
    PC pc;
    PCHK(KSPGetPC(ksp, &pc));
    static_cast<void>(pc);
    if (!configured_) {
      PCHK(KSPSetFromOptions(ksp));
      PCHK(KSPGetPC(ksp, &pc));
      PCHK(PCFieldSplitSetIS(pc, "u", is_u));
      PCHK(PCFieldSplitSetIS(pc, "p", is_p));
      PCHK(KSPSetInitialGuessNonzero(ksp, PETSC_TRUE));
      configured_ = true;
    }
    PCHK(KSPSetUp(ksp));
    PCHK(KSPGetPC(ksp, &pc));
    PetscInt nsplit = 0;
    KSP* sub = nullptr;
    PCHK(PCFieldSplitGetSubKSP(pc, &nsplit, &sub));
    if (cc && !shell_ready) {
      PC spc;
      PCHK(KSPGetPC(sub[1], &spc));
      PCHK(PCShellSetContext(spc, cc.get()));
      PCHK(PCShellSetSetUp(spc, cc_setup));
      PCHK(PCShellSetApply(spc, cc_apply));
      PCHK(PCShellSetName(spc, "Cahouet-Chabard (AMG(selfp) + mu lumped M_p^-1)"));
      shell_ready = true;
    }
    for (PetscInt k = 0; k < nsplit; ++k) PCHK(KSPSetUp(sub[k]));
    if (cc && !cc_first_done_) {  // the shell's set-up was not installed at the first KSPSetUp
      PC spc;
      PCHK(KSPGetPC(sub[1], &spc));
      PCHK(cc_setup(spc));
      cc_first_done_ = true;
    }
    PCHK(PetscFree(sub));
    return ms_since(t0);
  }
  // Solve from `guess`; returns ms, sets x and iterations.
  double solve(Vec b, Vec x, const Eigen::VectorXd& guess, int& iterations, int& reason) {
    to_vec(guess, x);
    const auto t0 = Clock::now();
    PCHK(KSPSolve(ksp, b, x));
    const double ms = ms_since(t0);
    PetscInt its = 0;
    PCHK(KSPGetIterationNumber(ksp, &its));
    KSPConvergedReason r;
    PCHK(KSPGetConvergedReason(ksp, &r));
    iterations = static_cast<int>(its);
    reason = static_cast<int>(r);
    return ms;
  }

 private:
  bool configured_ = false;
  bool cc_first_done_ = false;
};

struct Samples {
  std::vector<double> setup, solve, iterations, residual;
  int worst_reason = 1;
};

std::vector<int> parse_ints(const std::string& s) {
  std::vector<int> out;
  std::size_t i = 0;
  while (i < s.size()) {
    std::size_t j = s.find(',', i);
    if (j == std::string::npos) j = s.size();
    if (j > i) out.push_back(std::stoi(s.substr(i, j - i)));
    i = j + 1;
  }
  return out;
}
std::vector<std::string> parse_names(const std::string& s) {
  std::vector<std::string> out;
  std::size_t i = 0;
  while (i < s.size()) {
    std::size_t j = s.find(',', i);
    if (j == std::string::npos) j = s.size();
    if (j > i) out.push_back(s.substr(i, j - i));
    i = j + 1;
  }
  return out;
}

int run(int argc, char** argv) {
  double h = 0.05, hc = 0.006, dt = 0.002, ramp = 0.0, rtol = 1e-8, bicg_tol = 1e-10;
  int steps = 50, reps = 5;
  std::vector<int> lags{1, 5, 10};
  std::vector<std::string> selected;
  std::string lag_config;  // default: the first configuration run
  bool zero_guess = false;
  std::filesystem::path cache = std::filesystem::temp_directory_path() / "fsi_linear_solver_bench_meshes";
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto next = [&]() -> std::string {
      if (i + 1 >= argc) throw std::runtime_error("missing value after " + a);
      return argv[++i];
    };
    if (a == "--h")
      h = std::stod(next());
    else if (a == "--hc")
      hc = std::stod(next());
    else if (a == "--steps")
      steps = std::stoi(next());
    else if (a == "--dt")
      dt = std::stod(next());
    else if (a == "--reps")
      reps = std::stoi(next());
    else if (a == "--lags")
      lags = parse_ints(next());
    else if (a == "--ramp")
      ramp = std::stod(next());
    else if (a == "--configs")
      selected = parse_names(next());
    else if (a == "--rtol")
      rtol = std::stod(next());
    else if (a == "--bicgstab-tol")
      bicg_tol = std::stod(next());
    else if (a == "--lag-config")
      lag_config = next();
    else if (a == "--zero-guess")
      zero_guess = true;
    else if (a == "--cache")
      cache = next();
    else if (a.rfind("--", 0) == 0)
      throw std::runtime_error("unknown option " + a);
    // single-dash options belong to PETSc
  }
  for (int lag : lags)
    if (lag < 1 || lag >= steps) throw std::runtime_error("every lag must be in [1, steps - 1]");

  // 1. Mesh and solver: DFG 2D-2 with Taylor-Hood, as configs/dfg_2d2_p2p1.yaml.
  const auto msh =
      fsi::fluid::mesh_geo(FSI_SOURCE_DIR "/configs/meshes/dfg_cylinder.geo", {{"h", h}, {"hc", hc}}, cache, 2);
  const auto mesh = fsi::fluid::FluidMesh::from_gmsh(fsi::read_gmsh(msh));
  fsi::fluid::FlowParameters p;
  p.density = 1.0;
  p.viscosity = 1e-3;
  p.scheme = fsi::fluid::TimeScheme::BDF2;
  p.max_iterations = 1;
  p.newton = false;
  p.stabilisation.supg = false;
  p.stabilisation.pspg = false;
  p.stabilisation.lsic_scale = 0;
  p.ordering = fsi::fluid::Ordering::Amd;
  p.strategy = fsi::fluid::LuStrategy::Symmetric;
  fsi::fluid::TaylorHoodSolver solver(mesh, p);
  const double um = 1.5, height = 0.41;
  solver.add_dirichlet("inlet", [=](const Eigen::Vector2d& x, double t) {
    const double r = ramp > 0 && t < ramp ? 0.5 * (1 - std::cos(M_PI * t / ramp)) : 1.0;
    return Eigen::Vector2d(r * 4 * um * x.y() * (height - x.y()) / (height * height), 0);
  });
  const auto zero = [](const Eigen::Vector2d&, double) { return Eigen::Vector2d::Zero(); };
  solver.add_dirichlet("walls", zero);
  solver.add_dirichlet("cylinder", zero);
  const int n = solver.mesh().node_count(), nv = solver.mesh().vertices();
  const int N = solver.dofs();
  std::printf("mesh h %.4g hc %.4g: %d triangles, %d nodes (%d vertices), %d unknowns (%d velocity, %d pressure)\n", h,
              hc, solver.mesh().triangle_count(), n, nv, N, 2 * n, nv);

  // 2. K time steps; keep the matrices of the last steps and the extrapolated guess.
  std::map<int, SpMat> old;  // lag -> matrix of step K - lag
  Eigen::VectorXd u_km1, u_km2;
  const auto t_steps = Clock::now();
  for (int k = 1; k <= steps; ++k) {
    if (k == steps - 1) u_km2 = solver.solution();
    if (k == steps) u_km1 = solver.solution();
    solver.solve(k * dt, dt, solver.mesh().nodes, {});
    solver.accept();
    for (int lag : lags)
      if (k == steps - lag) old[lag] = solver.last_matrix();
  }
  const SpMat A = solver.last_matrix();
  const Eigen::VectorXd b = solver.last_rhs();
  const Eigen::VectorXd guess = zero_guess ? Eigen::VectorXd::Zero(N) : Eigen::VectorXd(2 * u_km1 - u_km2);
  std::printf("%d steps of dt %g (t = %g, inflow %s) in %.1f s; matrix: %ld nonzeros; guess: %s (residual %.2e)\n",
              steps, dt, steps * dt, ramp > 0 ? ("ramped over " + std::to_string(ramp)).c_str() : "impulsive",
              ms_since(t_steps) / 1e3, static_cast<long>(A.nonZeros()), zero_guess ? "zero" : "2 u_{K-1} - u_{K-2}",
              residual(A, guess, b));

  // Lumped P1 pressure mass (vertex positions; straight-sided approximation).
  Eigen::VectorXd lumped = Eigen::VectorXd::Zero(nv);
  for (int e = 0; e < solver.mesh().triangle_count(); ++e) {
    const auto& X = solver.mesh().nodes;
    const int a = solver.mesh().triangles(e, 0), bb = solver.mesh().triangles(e, 1), c = solver.mesh().triangles(e, 2);
    const Eigen::Vector2d e1 = X.row(bb) - X.row(a), e2 = X.row(c) - X.row(a);
    const double area = 0.5 * std::abs(e1.x() * e2.y() - e1.y() * e2.x());
    for (int v : {a, bb, c}) lumped(v) += area / 3;
  }

  // 3. PETSc objects.
  PetscMatrix PA(A);
  std::map<int, std::unique_ptr<PetscMatrix>> Pold;
  for (const auto& [lag, M] : old) Pold[lag] = std::make_unique<PetscMatrix>(M);
  Vec pb, px;
  PCHK(MatCreateVecs(PA.mat, &px, &pb));
  to_vec(b, pb);
  std::vector<PetscConfig> configs;
  for (const auto& c : petsc_configs(rtol))
    if (selected.empty() || std::find(selected.begin(), selected.end(), c.name) != selected.end()) configs.push_back(c);
  std::vector<std::unique_ptr<PetscSolver>> petsc;
  for (const auto& c : configs) petsc.push_back(std::make_unique<PetscSolver>(c, 2 * n, nv, lumped, p.viscosity));
  // Lagged preconditioner: one configuration's preconditioner built on the matrix of
  // step K - lag, applied to the current matrix (set up once; per step only the solve).
  std::map<int, std::unique_ptr<PetscSolver>> lagged;
  std::map<int, double> lagged_setup_ms;
  PetscConfig lag_base;
  for (const auto& c : petsc_configs(rtol))
    if (c.name == lag_config || (lag_config.empty() && !configs.empty() && c.name == configs.front().name))
      lag_base = c;
  if (!lag_config.empty() && lag_base.name.empty()) throw std::runtime_error("unknown --lag-config " + lag_config);
  if (!lag_base.name.empty())
    for (const auto& [lag, M] : Pold) {
      PetscConfig c = lag_base;
      c.name = c.name + "_lag" + std::to_string(lag);
      lagged[lag] = std::make_unique<PetscSolver>(c, 2 * n, nv, lumped, p.viscosity);
      lagged_setup_ms[lag] = lagged[lag]->setup(PA.mat, M->mat);
    }

  // UMFPACK factors of the old matrices for BiCGSTAB (as the project's reuse_factorisation).
  std::map<int, std::unique_ptr<Umf>> old_lu;
  for (const auto& [lag, M] : old) {
    old_lu[lag] = std::make_unique<Umf>();
    configure(*old_lu[lag]);
    old_lu[lag]->compute(M);
    if (old_lu[lag]->info() != Eigen::Success) throw std::runtime_error("UMFPACK failed on an old matrix");
  }

  // 4. Interleaved repetitions.
  Samples umf_symbolic, umf_numeric, umf_solve, umf_res;
  std::vector<Samples> ps(configs.size());
  std::map<int, Samples> lag_s, bicg_s;
  double update_ms_total = 0;
  for (int rep = 0; rep < reps; ++rep) {
    {  // (a) UMFPACK
      Umf lu;
      configure(lu);
      auto t0 = Clock::now();
      lu.analyzePattern(A);
      umf_symbolic.solve.push_back(ms_since(t0));
      t0 = Clock::now();
      lu.factorize(A);
      umf_numeric.solve.push_back(ms_since(t0));
      if (lu.info() != Eigen::Success) throw std::runtime_error("UMFPACK factorisation failed");
      t0 = Clock::now();
      const Eigen::VectorXd x = lu.solve(b);
      umf_solve.solve.push_back(ms_since(t0));
      umf_res.residual.push_back(residual(A, x, b));
    }
    for (std::size_t c = 0; c < configs.size(); ++c) {  // (b) PETSc, a "new" matrix each repetition
      const auto t0 = Clock::now();
      PA.update_values();
      update_ms_total += ms_since(t0);
      ps[c].setup.push_back(petsc[c]->setup(PA.mat, PA.mat));
      int its = 0, reason = 0;
      ps[c].solve.push_back(petsc[c]->solve(pb, px, guess, its, reason));
      ps[c].iterations.push_back(its);
      ps[c].residual.push_back(residual(A, from_vec(px), b));
      ps[c].worst_reason = std::min(ps[c].worst_reason, reason);
    }
    for (auto& [lag, s] : lagged) {  // PETSc with the preconditioner of step K - lag
      int its = 0, reason = 0;
      lag_s[lag].solve.push_back(s->solve(pb, px, guess, its, reason));
      lag_s[lag].iterations.push_back(its);
      lag_s[lag].residual.push_back(residual(A, from_vec(px), b));
      lag_s[lag].worst_reason = std::min(lag_s[lag].worst_reason, reason);
    }
    for (auto& [lag, lu] : old_lu) {  // (c) BiCGSTAB + UMFPACK factors of step K - lag
      Eigen::BiCGSTAB<SpMat, FrozenLu> krylov;
      krylov.preconditioner().set(lu.get());
      krylov.setTolerance(bicg_tol);  // default: the project's krylov_tolerance 1e-10
      krylov.setMaxIterations(200);
      const auto t0 = Clock::now();
      krylov.compute(A);
      const Eigen::VectorXd x = krylov.solveWithGuess(b, guess);
      bicg_s[lag].solve.push_back(ms_since(t0));
      bicg_s[lag].iterations.push_back(static_cast<double>(krylov.iterations()));
      bicg_s[lag].residual.push_back(residual(A, x, b));
      if (krylov.info() != Eigen::Success) bicg_s[lag].worst_reason = -1;
    }
  }

  // 5. Report (medians; residual: the largest).
  auto worst = [](const std::vector<double>& v) { return v.empty() ? NAN : *std::max_element(v.begin(), v.end()); };
  const double umf_factor = median(umf_symbolic.solve) + median(umf_numeric.solve);
  const double umf_sol = median(umf_solve.solve);
  std::printf(
      "\nmedians of %d interleaved repetitions, ms (ratios to UMFPACK numeric factorisation + solve = %.1f ms)\n", reps,
      median(umf_numeric.solve) + umf_sol);
  std::printf("%-22s %10s %10s %10s %6s %10s  %s\n", "solver", "setup", "solve", "total", "its", "residual", "ratio");
  const double ref = median(umf_numeric.solve) + umf_sol;
  std::printf("%-22s %10.1f %10.1f %10.1f %6s %10.2e  %.2f   (symbolic %.1f + numeric %.1f)\n", "umfpack_amd_sym",
              umf_factor, umf_sol, umf_factor + umf_sol, "-", worst(umf_res.residual), (umf_factor + umf_sol) / ref,
              median(umf_symbolic.solve), median(umf_numeric.solve));
  std::printf("%-22s %10.1f %10.1f %10.1f %6s %10.2e  %.2f\n", "umfpack_numeric_only", median(umf_numeric.solve),
              umf_sol, ref, "-", worst(umf_res.residual), 1.0);
  for (std::size_t c = 0; c < configs.size(); ++c) {
    const double su = median(ps[c].setup), so = median(ps[c].solve);
    std::printf("%-22s %10.1f %10.1f %10.1f %6.0f %10.2e  %.2f%s\n", configs[c].name.c_str(), su, so, su + so,
                median(ps[c].iterations), worst(ps[c].residual), (su + so) / ref,
                ps[c].worst_reason > 0 ? "" : "  (NOT CONVERGED)");
  }
  for (auto& [lag, s] : lag_s) {
    const std::string name = lag_base.name + "_pc_lag" + std::to_string(lag);
    std::printf("%-22s %10.1f %10.1f %10.1f %6.0f %10.2e  %.2f%s   (set-up on step K-%d, once)\n", name.c_str(),
                lagged_setup_ms[lag], median(s.solve), median(s.solve), median(s.iterations), worst(s.residual),
                median(s.solve) / ref, s.worst_reason > 0 ? "" : "  (NOT CONVERGED)", lag);
  }
  for (auto& [lag, s] : bicg_s) {
    const std::string name = "bicgstab_lu_lag" + std::to_string(lag);
    std::printf("%-22s %10s %10.1f %10.1f %6.0f %10.2e  %.2f%s   (UMFPACK factors of step K-%d, tol %.0e)\n",
                name.c_str(), "-", median(s.solve), median(s.solve), median(s.iterations), worst(s.residual),
                median(s.solve) / ref, s.worst_reason >= 0 ? "" : "  (NOT CONVERGED)", lag, bicg_tol);
  }
  std::printf("PETSc rtol %.0e (relative to ||b||, FGMRES: true residual)\n", rtol);
  std::printf("PETSc value copy into the AIJ matrix: %.2f ms per update\n",
              configs.empty() ? 0.0 : update_ms_total / (reps * static_cast<double>(configs.size())));
  for (std::size_t c = 0; c < configs.size(); ++c)
    std::printf("  %-14s %s\n", configs[c].name.c_str(), configs[c].description.c_str());

  PCHK(VecDestroy(&px));
  PCHK(VecDestroy(&pb));
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  if (PetscInitialize(&argc, &argv, nullptr, nullptr)) return 1;
  int rc = 0;
  try {
    rc = run(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "linear_solver_bench: %s\n", e.what());
    rc = 1;
  }
  PetscFinalize();
  return rc;
}
