#pragma once
// Coupling parameters of the seed paper (Kadapa): the algorithm (1 = explicit solid
// velocity in the Robin term, 2 = implicit, adding M_fs = gamma_N1 M_G to the solid),
// Nitsche parameters, relaxation beta, the force predictor and the iteration control.
#include <string>
#include <vector>

#include "fsi/common/config.hpp"
#include "fsi/common/scene_schema.hpp"
#include "fsi/coupling/interface_map.hpp"

namespace fsi::coupling {

enum class Algorithm { ExplicitSolidVelocity = 1, ImplicitSolidVelocity = 2 };
// The interface mass of the gamma_N1 terms on the solid's side: `consistent` = the fluid's
// own M_f in the configuration of its last solve, mapped H^T M_f H (the terms cancel exactly
// at convergence, any meshes, any deformation); `solid` = the solid's polyline int N^T N
// (Algorithm 1: current configuration; Algorithm 2: the solid's reference one), which leaves
// gamma_N1 (H^T M_f H - M_G) v_s in the converged solid equation (the earlier behaviour).
enum class RobinMass { Consistent, Solid };

// A convergence measure on one interface quantity (as preCICE's, per quantity):
//   force        the relaxed force update F^(k+1) - F^(k) (it includes the gamma_N1 terms)
//   traction     the physical traction: what the fluid's reaction H^T R exerts minus what the
//                solid felt (its load and its Robin damping), in the solid's nodal forces
//   displacement d_s^(k) - d_s^(k-1) (k = 1: against the last accepted step)
//   velocity     v_s^(k) - v_s^(k-1)
// and a test on the Euclidean norm |r| of that difference:
//   absolute |r| < limit; relative |r| / |q| < limit (q the quantity itself);
//   residual-relative |r_k| / |r_1| < limit (never at k = 1).
enum class MeasureQuantity { Force, Traction, Displacement, Velocity };
enum class MeasureType { Absolute, Relative, ResidualRelative };
struct ConvergenceMeasure {
  MeasureQuantity quantity = MeasureQuantity::Force;
  MeasureType type = MeasureType::Relative;
  double limit = 1e-4;
  bool strict = false;       // not met in k_max iterations = the run diverged
  std::string name() const;  // e.g. "traction_relative" (its iterations.csv column)
};

// The interface quasi-Newton schemes' options (coupling.iqn; preCICE's semantics):
//   filter of the secant columns (newest first), with limit eps:
//     qr1  after the QR decomposition, drop columns with |R_ii| < eps ||R||_F (repeatedly)
//     qr2  orthogonalise newest first, drop a column whose remainder is < eps x its own norm
//     qr3  qr2's result, found by updating the last iteration's QR with the new column and
//          running qr2 only when a column fails the test (or the preconditioner changed)
//   preconditioner: none, or residual-sum (each force component x, y weighted by the inverse
//     of the sum over the step's iterations of its share of the residual norm; the weights
//     change only by more than a factor 10).
enum class QrFilter { Qr1, Qr2, Qr3 };
enum class Preconditioner { None, ResidualSum };
// IQN-IMVJ (coupling.iqn.imvj): without restart the inverse Jacobian J_n (dense, n x n)
// carries over from step to step; a restart mode keeps only the last `chunk_size` steps'
// updates and then restarts: rs-0 from zero, rs-ls from the least-squares Jacobian of the
// last `restart_reuse_steps` steps' secant pairs, rs-svd from a truncated SVD of the
// accumulated update (singular values below `truncation` x the largest are dropped).
enum class ImvjRestart { None, Zero, LeastSquares, Svd };
// The order of the two solves in a coupling iteration (coupling.scheme):
//   serial    the solid with F^(k), then the fluid with the solid's new interface state
//             (Gauss-Seidel; the seed paper). The accelerator works on the force F.
//   parallel  both at once (Jacobi): the solid with F^(k), the fluid with the interface state
//             x^(k) = (d^(k), v^(k)); the accelerator works on the stacked [d; v; F], each
//             block scaled by its size (preCICE's parallel implicit coupling). With one
//             iteration per step it is a parallel explicit scheme: the fluid gets the
//             predicted d_n + dt v_n, v_n.
//   robin-neumann  explicit (one pass per step, no iterations): the fluid with the Robin
//             condition f_sigma + A v_f = A v* + f* (A the solid's interface mass over dt, v*
//             and f* extrapolated from the accepted steps), then the solid with the fluid's
//             traction (the generalised Robin-Neumann scheme of Fernandez, Mullaert and
//             Vidrascu 2015). robin_neumann_order 1 or 2 is the extrapolation's order.
enum class CouplingScheme { Serial, Parallel, RobinNeumann };
// The automatic Robin parameter (coupling.robin_auto): gamma_auto = (m_s / |Gamma|) / dt, the
// solid's mass per interface measure (as the solid reports it) over the time step, replaces
// gamma_N1 (the solid side: Algorithm 2's damping and its lagged Robin term), the fluid's
// penalty gamma_f (the fluid side) or both.
enum class RobinAuto { None, Solid, Fluid, Both };

struct CouplingSettings {
  Algorithm algorithm = Algorithm::ExplicitSolidVelocity;
  CouplingScheme scheme = CouplingScheme::Serial;
  RobinAuto robin_auto = RobinAuto::None;
  int robin_neumann_order = 1;
  double gamma_n1 = 0;  // gamma_N1 >= 0
  // The fluid's Nitsche penalty gamma_f (its weak no-slip v_f = v_s on the interface). The
  // paper uses one parameter: gamma_f = gamma_N1 (the default). Set apart, the converged
  // coupled solution no longer depends on the Robin parameter gamma_N1 of Algorithm 2.
  double gamma_f = 0;
  double gamma_n2 = -1;  // gamma_N2 = +1 symmetric, -1 unsymmetric (the paper)
  double beta = 1;       // beta in (0, 1]
  // F^(1)_{n+1} from the accepted forces: a name of predictor.hpp's registry ("previous" =
  // F_n, the paper).
  std::string predictor = "previous";
  // How F^(k+1) follows from F^(k) and F*: a name of acceleration.hpp's registry ("constant" =
  // the paper's beta; Aitken and the quasi-Newton schemes are beyond the paper and start each
  // step with beta).
  std::string acceleration = "constant";
  int reuse_steps = 8;       // quasi-Newton: secant pairs of the last N accepted steps are reused
  double iqn_filter = 1e-3;  // quasi-Newton: the filter's limit eps
  QrFilter iqn_filter_type = QrFilter::Qr2;
  Preconditioner iqn_preconditioner = Preconditioner::None;
  ImvjRestart imvj_restart = ImvjRestart::None;
  int imvj_chunk_size = 8;           // restart after this many steps
  int imvj_restart_reuse_steps = 8;  // rs-ls: the steps whose secant pairs define the restart
  double imvj_truncation = 1e-4;     // rs-svd: relative truncation of the singular values
  int max_iterations = 1;            // k_max
  // 0: exactly max_iterations iterations per step (the paper). > 0: iterate until the
  // relative interface residual ||F^(k+1) - F^(k)|| / ||F^(k+1)|| is below it.
  double tolerance = 0;
  bool stop_if_not_converged = true;  // with a tolerance: not converged in k_max = diverged
  double divergence_factor = 1e4;     // residual growth over the step's first residual
  double force_limit = 1e12;          // |F| above this = diverged (loosely coupled blow-up)
  // coupling.growth: max |d| of the last window steps > factor x that of the window before = diverged
  double growth_factor = 1000;
  int growth_window = 200;
  // coupling.interface_gap: the fluid's largest gap to the solid's interface, as a fraction of
  // the solid interface's median element size: warn above gap_warn, refuse above gap_refuse (0 = never)
  double gap_warn = 0.05;
  double gap_refuse = 0.5;
  double residual_floor = 1e-14;  // absolute floor of the residual's denominator
  RobinMass robin_mass = RobinMass::Consistent;
  // iterations.measures (or, without it, iterations.tolerance as {force, relative}); empty =
  // always k_max iterations (the paper).
  std::vector<ConvergenceMeasure> measures;
  bool combine_all = true;  // iterations.combine: all measures must hold, or any
  // coupling.mapping (and coupling.support_radius): how interface values move between the
  // solid's and the fluid's nodes (interface_map.hpp).
  MappingSettings mapping;
};

// Reads the `coupling` section through its declaration (coupling_keys.cpp).
CouplingSettings read_coupling(const ConfigSection& section);
// The `coupling` section's declaration; the first call declares it to the scene schema.
const schema::Key& coupling_section();

std::string to_string(Algorithm a);
std::string to_string(RobinMass m);

}  // namespace fsi::coupling
