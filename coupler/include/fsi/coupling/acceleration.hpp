#pragma once
// How the coupler's interface fixed-point iteration F^(k+1) = G(F^(k)) is updated from the
// residual r_k = -F*(F^(k)) - F^(k):
//  - constant: F^(k+1) = F^(k) + beta r_k (the seed paper);
//  - aitken:   omega_k from the last two residuals (Kuttler & Wall 2008), starting at beta;
//  - iqn-ils:  interface quasi-Newton with a least-squares model of the inverse Jacobian
//              (Degroote, Bathe & Vierendeels 2009), optionally reusing the secant pairs of
//              the last `reuse_steps` time steps. Its first iteration, with no secant pair
//              yet, is the constant relaxation beta.
// Pure linear algebra: no knowledge of solvers, messages or time.
#include <Eigen/Core>

#include <deque>

#include "fsi/common/state.hpp"
#include "fsi/coupling/settings.hpp"

namespace fsi::coupling {

class InterfaceAccelerator {
 public:
  explicit InterfaceAccelerator(const CouplingSettings& settings) : settings_(settings) {}
  // Called at each step's first iteration.
  void begin_step();
  // x = F^(k), r = G(F^(k)) - F^(k); returns F^(k+1).
  Eigen::VectorXd update(const Eigen::VectorXd& x, const Eigen::VectorXd& r);
  // Called when the step is accepted: IQN-ILS keeps this step's secant pairs for reuse.
  void end_step();
  // The relaxation factor of the last update (constant/Aitken); 0 for a quasi-Newton update.
  double last_omega() const { return last_omega_; }
  // Secant pairs used by the last quasi-Newton update (after filtering).
  int last_columns() const { return last_columns_; }
  // What carries over from one step to the next (the reused secant pairs, the last factor),
  // for checkpoints: entries named "<prefix>...". Call between steps.
  void save(StateArchive& state, const std::string& prefix) const;
  void load(const StateArchive& state, const std::string& prefix);

 private:
  Eigen::VectorXd quasi_newton(const Eigen::VectorXd& x, const Eigen::VectorXd& r);

  CouplingSettings settings_;
  int k_ = 0;
  Eigen::VectorXd previous_r_, previous_xt_;  // r and x~ = x + r of the last iteration
  double last_omega_ = 0;
  int last_columns_ = 0;
  // Secant pairs (dr, dx~), newest first: this step's, then earlier steps' (newest first).
  std::deque<Eigen::VectorXd> v_step_, w_step_;
  std::deque<std::deque<Eigen::VectorXd>> v_old_, w_old_;
};

}  // namespace fsi::coupling
