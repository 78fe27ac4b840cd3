#pragma once
// The fluid solver: Navier-Stokes in ALE form on a (moving) triangle mesh, with strong
// Dirichlet and symmetry conditions, do-nothing outlets, a Nitsche interface, BDF1/BDF2,
// Picard or Newton iterations, a linear-algebra engine (linear_solver.hpp: UMFPACK, PETSc,
// MUMPS) and consistent reaction forces. One time-stepping, assembly, interface and checkpoint
// path for both elements:
//   "p1p1" - equal-order P1/P1 with SUPG/PSPG/LSIC (the seed paper's element; NavierStokesSolver)
//   "p2p1" - isoparametric Taylor-Hood P2/P1 (inf-sup stable; optional SUPG, grad-div; TaylorHoodSolver)
// whose element parts (local assembly, DOF layout, interface traces, output) sit behind one
// interface (src/flow_element.hpp). Pure numerics: Eigen in, Eigen out; no configuration
// files, sockets or output. NavierStokesFluid (navier_stokes_fluid.hpp) wraps it for scenes.
//
// Use:
//   FlowSolver solver(mesh, params, "p1p1");
//   solver.add_dirichlet("inlet", profile);  solver.add_dirichlet("walls", zero);
//   solver.set_interface({"flag"});                    // Nitsche groups (optional)
//   for each step:  solver.solve(t, dt, positions, interface_velocity);  (repeatable)
//                   solver.accept();
//
// Linearisation: per solve, `max_iterations` Picard (Oseen) or Newton iterations; the first
// one advects with the extrapolated velocity (BDF2: (1+w) u_n - w u_{n-1}), so one iteration
// per step is the second-order semi-implicit scheme (one factorisation per step).
#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <array>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "fsi/common/solver_model.hpp"
#include "fsi/common/state.hpp"
#include "fsi/fluid/mesh.hpp"
#include "fsi/fluid/tet_mesh.hpp"

namespace fsi::fluid {

struct TransferReport;  // field_transfer.hpp

// The dimension is a template parameter of the solver (FlowSolver: 2D triangles, FlowSolver3:
// 3D tetrahedra); a point, the nodal values of a vector field and the mesh follow from it.
template <int Dim>
using Point = Eigen::Matrix<double, Dim, 1>;
template <int Dim>
using NodeMatrix = Eigen::Matrix<double, Eigen::Dynamic, Dim>;  // one row per node
template <int Dim>
struct MeshType;
template <>
struct MeshType<2> {
  using type = FluidMesh;
};
template <>
struct MeshType<3> {
  using type = TetMesh;
};
template <int Dim>
using MeshOf = typename MeshType<Dim>::type;

template <int Dim>
using VelocityFunctionT = std::function<Point<Dim>(const Point<Dim>& x, double t)>;
using VelocityFunction = VelocityFunctionT<2>;

enum class TimeScheme { Steady, BDF1, BDF2 };

// The mesh motion of a step folded an element of the moving mesh (the step's positions, not the
// accepted ones): a SolverError that remeshing the step-start mesh may cure.
class MeshTangled : public SolverError {
 public:
  using SolverError::SolverError;
};

struct StabilisationParameters {
  bool supg = true;
  bool pspg = true;               // P1/P1 only (Taylor-Hood is inf-sup stable)
  double lsic_scale = 1.0;        // P1/P1: multiplies tau_C = h^2 / (8 tau_M); 0 switches LSIC off
  double grad_div = 0.0;          // P2/P1: gamma in gamma (div w, div u) (units of a dynamic viscosity)
  double viscous_constant = 3.0;  // c in tau_M^-2 = (2/dt)^2 + (2|a|/h)^2 + (c 4 nu/h^2)^2
  bool transient_tau = true;      // include the (2/dt)^2 term
  bool viscous_residual = false;  // P1/P1: include the reconstructed div(mu grad u*) in r_M
};

// Fill-reducing ordering of the sparse LU (UMFPACK); Auto tries both on the first matrix and
// keeps the one whose factorisation needs fewer flops.
enum class Ordering { Amd, Metis, Auto };
// UMFPACK's strategy: Symmetric (AMD/METIS on A + A^T, diagonal pivots preferred) suits both
// elements' saddle-point matrices (measured: 20 % faster factorisations, 30 % faster solves
// than Auto on Taylor-Hood); Auto lets UMFPACK decide from the pattern.
enum class LuStrategy { Auto, Symmetric, Unsymmetric };
// The linear-algebra engine (linear_solver.hpp): UMFPACK (sparse_lu.hpp), a PETSc Krylov solver
// (field-split preconditioner by default), or MUMPS through PETSc.
enum class LinearEngine { Umfpack, Petsc, Mumps };

struct FlowParameters {
  double density = 1.0;
  double viscosity = 1e-3;  // dynamic
  TimeScheme scheme = TimeScheme::BDF2;
  int max_iterations = 1;    // nonlinear solves per step
  double tolerance = 1e-10;  // stop when the relative velocity change falls below
  // Newton: the exact Jacobian of the Galerkin convection term ((du . grad) u_k added to the
  // Oseen operator); false: Picard (Oseen) iterations. The first solve of a time step always
  // advects with the extrapolated velocity, so max_iterations = 1 is the semi-implicit scheme.
  bool newton = false;
  // A repeated solve of the same time level (a coupling iteration) linearises about the last
  // solve's velocity instead of the extrapolation, so converged coupling iterations give the
  // fully implicit step (at no extra solve); false: every coupling iteration is semi-implicit.
  bool relinearise = false;
  StabilisationParameters stabilisation;
  double nitsche_penalty = 0;    // gamma_N1
  double nitsche_symmetry = -1;  // gamma_N2 (+1 symmetric, -1 unsymmetric)
  // The penalty term gamma_N1 int w . (v - v_s) (and f_v, and the interface mass sent to the
  // coupler) on the interface of the last accepted step instead of the current one: the
  // coupler's M_G = H^T M_f H is then constant within a time step, so Algorithm 2's
  // iterations do not see gamma_N1 dM/dx (robust converged coupling at large gamma_N1). The
  // consistency and symmetry terms stay on the current interface.
  bool penalty_on_step_start = false;
  int threads = 1;
  int umfpack_irstep = 0;
  Ordering ordering = Ordering::Auto;
  LuStrategy strategy = LuStrategy::Auto;
  // Reuse the last LU factors as the preconditioner of BiCGSTAB on the new matrix; refactorise
  // only when BiCGSTAB needs more than krylov_max_iterations (or on the first solve).
  bool reuse_factorisation = true;
  double krylov_tolerance = 1e-10;  // relative residual
  int krylov_max_iterations = 25;
  int krylov_refactor_iterations = 8;  // a solve needing more marks the factors stale: refactorise next time
  // Refactorise as soon as a Krylov solve costs more than the average cost per solve of the
  // current factors (their factorisation included): minimises the cost per step. Costs are
  // counted in flops, not measured, so the decisions are reproducible (sparse_lu.hpp).
  bool adaptive_refactorisation = true;
  LinearEngine engine = LinearEngine::Umfpack;
  // PETSc engines: options after the engine's defaults (default_petsc_options), e.g.
  // "-ksp_rtol 1e-12 -fieldsplit_p_pc_type gamg"; an option the solver leaves unused is an error.
  std::string petsc_options;
  // PETSc engines: keep the preconditioner of an earlier matrix while the iterations stay below
  // petsc_rebuild_factor x those of its first solve (+ 5) (and it converges); else rebuild.
  bool petsc_reuse_preconditioner = true;
  double petsc_rebuild_factor = 1.5;
  // PETSc engines on several MPI ranks, 3D: every rank computes the element matrices of its
  // block of cells (false: rank 0 assembles alone, as 2D always does). Partitioned: each rank
  // keeps only its cells (a mesh of their own) and adds their matrices straight into the
  // distributed matrix; otherwise rank 0 sums the blocks into the whole matrix.
  bool distributed_assembly = true;
  bool partitioned_assembly = true;
  // Backflow stabilisation of the traction-free boundaries (outlets, and pressure boundaries
  // while their pressure is 0; 3D): where the fluid enters through them ((u - w).n < 0) their
  // traction gains beta rho ((u - w).n)_- u
  // (Bazilevs et al. 2009; Esmaily Moghadam et al. 2011), with u's flux from the linearisation
  // velocity. 0: off (the plain traction condition).
  double backflow_beta = 0;
  // Tests only (the GCL tests' control): the ALE mesh velocity is multiplied by this; anything
  // but 1 is a wrong mesh velocity, which a GCL test must detect.
  double mesh_velocity_scale = 1.0;
};

struct StepReport {
  int iterations = 0;
  double change = 0;  // last relative velocity change
  double assembly_seconds = 0;
  double factor_seconds = 0;
  double solve_seconds = 0;
  int factorisations = 0;
  int krylov_iterations = 0;
};

template <int Dim>
class BasicFlowSolver {
 public:
  using Mesh = MeshOf<Dim>;
  using PointD = Point<Dim>;
  using Nodes = NodeMatrix<Dim>;
  using Velocity = VelocityFunctionT<Dim>;
  // `element`: 2D "p1p1" (3-node triangles) or "p2p1" (6-node triangles; a linear mesh gets
  // straight midpoints); 3D "p2p1" (10-node tetrahedra; a linear mesh gets straight midpoints).
  // std::invalid_argument when the mesh does not suit the element.
  BasicFlowSolver(Mesh mesh, FlowParameters params, const std::string& element);
  ~BasicFlowSolver();
  BasicFlowSolver(BasicFlowSolver&&) noexcept;
  BasicFlowSolver& operator=(BasicFlowSolver&&) noexcept;

  // --- set-up (before the first solve) ---
  void add_dirichlet(const std::string& group, Velocity velocity);  // strong, both components
  void add_symmetry(const std::string& group);                      // u.n = 0 (axis-aligned)
  // A prescribed normal traction sigma n = -p(t) n on a boundary group (a pressure inlet or
  // outlet; Taylor-Hood only). The rest of the boundary without conditions is do-nothing (p = 0).
  void add_pressure(const std::string& group, std::function<double(double)> pressure);
  // A traction-free (do-nothing) boundary: nothing to add, unless FlowParameters::backflow_beta
  // > 0 stabilises it (its faces are kept for that).
  void add_open_boundary(const std::string& group);
  void set_interface(const std::vector<std::string>& groups);                             // Nitsche groups
  void set_pressure_reference(const PointD& point, std::function<double(double)> value);  // nearest vertex
  void set_body_force(Velocity force);
  void set_initial_velocity(const Nodes& velocity);  // per node
  // Called after each nonlinear iteration of solve() with the iteration and the relative change.
  void set_iteration_observer(std::function<void(int, double)> observer) { observer_ = std::move(observer); }

  // --- stepping ---
  // Solves time level `time` (= t_n + dt) from the accepted state, on the mesh at `positions`
  // (every node, current configuration), with the interface velocity per interface node
  // (interleaved, 2 * interface_nodes().size(); empty = zero). Repeatable before accept().
  StepReport solve(double time, double dt, const Nodes& positions, const Eigen::VectorXd& interface_velocity);
  // The time level with a Robin condition on the interface instead of Nitsche's terms
  // (the explicit Robin-Neumann coupling; RobinCondition, solver_model.hpp): at every
  // interface node j, lumped,
  //   f_sigma_j + A_j v_j = A_j v*_j + f*_j,   A_j = coefficient_j int_Gamma N_j
  // (int N_j: the row sum of interface_mass() on the current interface), added to the node's
  // momentum rows; no consistency, symmetry or penalty terms. f_sigma is then the reaction
  // alone (interface_traction()). Nodes with a strong condition keep it. 2D only: on 6-node
  // faces (3D) int N_j of a vertex is 0.
  StepReport solve_robin(double time, double dt, const Nodes& positions, const RobinCondition& robin);
  void accept();

  // --- checkpoints (after accept()) ---
  // Writes everything the next solve depends on under `prefix` (e.g. "flow.": flow.element,
  // flow.u, flow.u_n, flow.x_n, ..., and the linear solver's flow.lu.ordering) and drops the LU
  // factors, so that the next solve refactorises, exactly as a solver restored from this state does.
  void save_state(StateArchive& state, const std::string& prefix);
  // On a solver set up like the saved one (same mesh, conditions and parameters), before any
  // solve: continues bit for bit as the saved one. fsi::StateError (naming the entry) when
  // the state does not fit (another element or mesh); the solver is then unchanged.
  void load_state(const StateArchive& state, const std::string& prefix);
  // Remeshing (remesh.hpp): this solver, set up on a new mesh of the same domain with the old
  // one's conditions and interface and not yet stepped, takes the accepted state of `old`:
  // velocity and pressure of the last two accepted steps (the BDF history) and the last
  // step's mesh displacement x_n - x_{n-1} (so the BDF mesh velocity carries over),
  // interpolated with the old element's own shape functions at the new nodes
  // (field_transfer.hpp; P2 velocity and P1 pressure for P2/P1, P1 for P1/P1), copied at the
  // nodes `old_node` names (the kept boundary nodes: -1 = a new node); the step counts and
  // sizes and the interface velocity. The new mesh's reference positions are its current ones.
  // The reactions restart at zero (the next solve makes them). Returns the interpolation report.
  TransferReport transfer_state(const BasicFlowSolver& old, const std::vector<int>& old_node);
  // A fresh start from the present velocity and pressure (after transfer_state from another
  // run's state): no history (the next step is BDF1), the mesh at rest, no interface velocity.
  void restart_history();
  // Waveform windows (NavierStokesFluid::solve_window): the stepping state (solution, BDF
  // history, positions, step sizes and counts, interface velocity) as a snapshot in memory, and
  // back; the linear solver is left as it is (its factors stay in use).
  struct History {
    Eigen::VectorXd U, U_n, U_nm1, reaction, interface_velocity;
    Nodes X, X_n, X_nm1;
    double dt_n = 0, dt_trial = 0;
    int accepted = 0, trial_solves = 0;
    bool robin = false;
  };
  History history() const;
  void set_history(const History& h);
  // Waveform windows with penalty_on_step_start: true = the penalty term's interface (and
  // interface_mass()) stays where the last accepted step left it at this call (the window's
  // start) through the substeps accepted after it, as the solid's damping M_G stays for the whole
  // window; false (the default) = on the last accepted step's interface.
  void hold_penalty_interface(bool hold);

  // --- results of the last solve ---
  const Mesh& mesh() const;
  const FlowParameters& parameters() const { return params_; }
  int dofs() const;
  // Every unknown: P1/P1 (u, v, p) per node; P2/P1 (u, v) per node at 2 i, 2 i + 1, then p per vertex.
  const Eigen::VectorXd& solution() const { return U_; }
  // The MPI ranks that compute the element matrices (1: this process alone; FlowParameters::
  // distributed_assembly).
  int assembly_ranks() const;
  const Eigen::VectorXd& reaction() const { return reaction_; }  // K_vol U - F_vol, every unknown
  // The system of the last solve (constraints applied) and its right-hand side (benchmarks; empty
  // with the partitioned assembly on several ranks, where no rank holds the whole matrix).
  const Eigen::SparseMatrix<double>& last_matrix() const;
  const Eigen::VectorXd& last_rhs() const;
  Nodes velocity() const;            // per node
  Eigen::VectorXd pressure() const;  // per node (P2/P1: linear between the vertices)
  const Nodes& positions() const { return X_; }
  const Nodes& accepted_positions() const { return X_n_; }
  // Force of the fluid on the body bounded by the groups: minus the sum of the momentum
  // reactions (residual of the volume terms) over the groups' nodes (consistent reaction forces).
  PointD force(const std::vector<std::string>& groups) const;
  // Interface nodes (P2/P1: vertices and edge midpoints) and their segments (local indices;
  // P2/P1: every edge split at its midpoint).
  const std::vector<int>& interface_nodes() const { return interface_nodes_; }
  const IndexMatrix2& interface_segments() const { return interface_segments_; }
  // 3D: the interface faces, 6-node triangles on the interface indices (gmsh order: the
  // vertices a, b, c as in the mesh's boundary group, then the midpoints of ab, bc, ca).
  const std::vector<std::array<int, 6>>& interface_faces() const { return interface_faces_; }
  // f_sigma = int N^T sigma n (n = fluid outward normal), the reaction plus the penalty term
  // gamma_N1 int N^T (v_f - v_s) (after a Robin solve the reaction alone); f_v = int N^T v_f
  // at the interface nodes (current configuration).
  Eigen::VectorXd interface_traction() const;
  Eigen::VectorXd interface_velocity_integral() const;
  // M_f = int N_i N_j dgamma over the interface in the configuration of the last solve, with
  // the quadrature of the Nitsche terms (a scalar matrix on the interface nodes): f_v = M_f v_f
  // and the penalty part of f_sigma is gamma_N1 M_f (v_f - v_s).
  Eigen::SparseMatrix<double> interface_mass() const;
  double pressure_at(const PointD& point) const;  // NaN outside the mesh
  PointD velocity_at(const PointD& point) const;

 private:
  struct Impl;
  struct Step;
  FlowParameters params_;
  std::unique_ptr<Impl> impl_;
  Eigen::VectorXd U_, U_n_, U_nm1_, reaction_;
  Nodes X_, X_n_, X_nm1_;
  double dt_n_ = 0;      // last accepted step size
  double dt_trial_ = 0;  // step size of the last solve
  int accepted_ = 0;
  int trial_solves_ = 0;  // solves of the current time level since the last accept()
  std::vector<int> interface_nodes_;
  IndexMatrix2 interface_segments_;
  std::vector<std::array<int, 6>> interface_faces_;
  Eigen::VectorXd interface_velocity_;  // of the last solve (a Robin solve: v*)
  Nodes X_penalty_;                     // hold_penalty_interface(true): the held interface
  bool hold_penalty_ = false;
  const Nodes& penalty_positions() const { return hold_penalty_ ? X_penalty_ : X_n_; }
  bool robin_ = false;  // the last solve had a Robin interface condition
  std::function<void(int, double)> observer_;
  Step begin_step(double time, double dt, const Nodes& positions, const Eigen::VectorXd& interface_velocity);
  StepReport solve(Step& step);
  void assemble(const Step& step, const Eigen::VectorXd& U_lin, StepReport& report);
  void fill_partitioned(const Step& step);  // 3D on several ranks (FlowParameters::partitioned_assembly)
  Eigen::VectorXd partitioned_reaction();
  bool locate(const PointD& point, int& element, Eigen::Matrix<double, Dim + 1, 1>& bary) const;
};

using FlowSolver = BasicFlowSolver<2>;
using FlowSolver3 = BasicFlowSolver<3>;  // no remeshing yet
extern template class BasicFlowSolver<2>;
extern template class BasicFlowSolver<3>;

}  // namespace fsi::fluid
