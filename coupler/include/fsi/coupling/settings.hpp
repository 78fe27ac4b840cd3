#pragma once
// Coupling parameters of the seed paper (Kadapa): the algorithm (1 = explicit solid
// velocity in the Robin term, 2 = implicit, adding M_fs = gamma_N1 M_G to the solid),
// Nitsche parameters, relaxation beta, the force predictor and the iteration control.
#include <string>

#include "fsi/common/config.hpp"

namespace fsi::coupling {

enum class Algorithm { ExplicitSolidVelocity = 1, ImplicitSolidVelocity = 2 };
enum class Predictor { Previous, Linear };
// How F^(k+1) follows from F^(k) and F*: the paper's constant relaxation, Aitken's dynamic
// relaxation (Kuttler & Wall 2008) or interface quasi-Newton IQN-ILS (Degroote et al. 2009),
// both beyond the paper and both starting each step with beta (acceleration.hpp).
enum class Acceleration { Constant, Aitken, IqnIls };

struct CouplingSettings {
  Algorithm algorithm = Algorithm::ExplicitSolidVelocity;
  double nitsche_penalty = 0;     // gamma_N1 >= 0
  double nitsche_symmetry = -1;   // gamma_N2 = +1 symmetric, -1 unsymmetric (the paper)
  double relaxation = 1;          // beta in (0, 1]
  Predictor predictor = Predictor::Previous;  // F^(1)_{n+1} = F_n (the paper)
  Acceleration acceleration = Acceleration::Constant;
  int reuse_steps = 8;            // IQN-ILS: secant pairs of the last N accepted steps are reused
  double iqn_filter = 1e-3;       // IQN-ILS: drop a column whose orthogonal remainder is below this share
  int max_iterations = 1;         // k_max
  // 0: exactly max_iterations iterations per step (the paper). > 0: iterate until the
  // relative interface residual ||F^(k+1) - F^(k)|| / ||F^(k+1)|| is below it.
  double tolerance = 0;
  bool stop_if_not_converged = true;  // with a tolerance: not converged in k_max = diverged
  double divergence_factor = 1e4;     // residual growth over the step's first residual
  double force_limit = 1e12;          // |F| above this = diverged (loosely coupled blow-up)
  double residual_floor = 1e-14;      // absolute floor of the residual's denominator
};

// Reads the `coupling` section (every key documented in configs/sdof_model.yaml).
CouplingSettings read_coupling(const ConfigSection& section);

std::string to_string(Algorithm a);
std::string to_string(Acceleration a);

}  // namespace fsi::coupling
