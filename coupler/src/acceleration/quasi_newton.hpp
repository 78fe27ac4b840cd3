#pragma once
// What the interface quasi-Newton schemes share: the secant pairs (dr_i, dx~_i) of the step's
// iterations (differences of consecutive residuals r and outputs x~ = x + r = G(x)), those of
// the last `reuse_steps` accepted steps, their orthogonalisation with a filter, and their
// place in checkpoints. A scheme says what its update does with them (quasi_newton_update).
#include <Eigen/Core>

#include <deque>
#include <vector>

#include "fsi/coupling/acceleration.hpp"

namespace fsi::coupling {

class QuasiNewton : public Accelerator {
 public:
  void begin_step() override;
  Eigen::VectorXd update(const Eigen::VectorXd& x, const Eigen::VectorXd& r) override;
  void end_step() override;
  void save(StateArchive& state, const std::string& prefix) const override;
  void load(const StateArchive& state, const std::string& prefix) override;

 protected:
  using Accelerator::Accelerator;
  // The scheme's F^(k+1) from x = F^(k), r and x~ = x + r, the step's pair already recorded.
  virtual Eigen::VectorXd quasi_newton_update(const Eigen::VectorXd& x, const Eigen::VectorXd& r,
                                              const Eigen::VectorXd& xt) = 0;
  // The secant pairs, this step's then the reused steps' (newest first), orthogonalised by
  // modified Gram-Schmidt: V_kept = Q R, with W's matching columns. A column whose remainder
  // is below `iqn_filter` times its own norm is (nearly) dependent on newer information and
  // is dropped (at most n columns are kept).
  struct Columns {
    Eigen::MatrixXd q, r;                 // n x m_max and m_max x m_max; the first m are used
    std::vector<const Eigen::VectorXd*> v, w;  // the kept columns of V and W
    Eigen::Index m = 0;
  };
  Columns filtered_columns(Eigen::Index n) const;

  Eigen::VectorXd previous_r_, previous_xt_;  // r and x~ of the step's last iteration
  // Secant pairs (dr, dx~), newest first: this step's, then earlier steps' (newest first).
  std::deque<Eigen::VectorXd> v_step_, w_step_;
  std::deque<std::deque<Eigen::VectorXd>> v_old_, w_old_;
};

}  // namespace fsi::coupling
