#pragma once
// What the interface quasi-Newton schemes share: the secant pairs (dr_i, dx~_i) of the step's
// iterations (differences of consecutive residuals r and outputs x~ = x + r = G(x)), those of
// the last `reuse_steps` accepted steps, their filtered QR decomposition (qr1, qr2, qr3), the
// residual-sum preconditioner, and their place in checkpoints. A scheme says what its update
// does with them (quasi_newton_update).
#include <Eigen/Core>
#include <deque>
#include <vector>

#include "fsi/coupling/acceleration.hpp"

namespace fsi::coupling {

class QuasiNewton : public Accelerator {
 public:
  explicit QuasiNewton(const CouplingSettings& settings) : Accelerator(settings) {}
  void begin_step() override;
  Eigen::VectorXd update(const Eigen::VectorXd& x, const Eigen::VectorXd& r) override;
  void end_step() override;
  void save(StateArchive& state, const std::string& prefix) const override;
  void load(const StateArchive& state, const std::string& prefix) override;

 protected:
  // The scheme's F^(k+1) from x = F^(k), r and x~ = x + r, the step's pair already recorded.
  virtual Eigen::VectorXd quasi_newton_update(const Eigen::VectorXd& x, const Eigen::VectorXd& r,
                                              const Eigen::VectorXd& xt) = 0;
  // The scheme's name in checkpoints: state saved by another scheme is not loaded.
  virtual const char* scheme() const = 0;
  // The secant pairs, this step's then the reused steps' (newest first), filtered, with the
  // QR decomposition of the kept columns of V in the preconditioner's scaling:
  // P V_kept = Q R (P = diag(weights)), W's matching columns alongside. At most n columns.
  struct Columns {
    Eigen::MatrixXd q, r;                      // n x m_max and m_max x m_max; the first m are used
    std::vector<const Eigen::VectorXd*> v, w;  // the kept columns of V and W
    Eigen::Index m = 0;
  };
  const Columns& filtered_columns(Eigen::Index n);
  // The same filter (qr1 or qr2, never incremental) on any columns, newest first.
  Columns filter_columns(const std::vector<const Eigen::VectorXd*>& v, const std::vector<const Eigen::VectorXd*>& w,
                         Eigen::Index n) const;
  // The least-squares coefficients: R alpha = Q^T P y (so that V alpha ~ y in P's norm).
  Eigen::VectorXd solve(const Columns& c, const Eigen::VectorXd& y) const;
  // Z = R^-1 Q^T P (m x n): the pseudo-inverse of V in P's norm, Z V = I.
  Eigen::MatrixXd pseudo_inverse(const Columns& c) const;
  // The preconditioner's weight per entry (1 without one).
  Eigen::VectorXd scaled(const Eigen::VectorXd& y) const;

  Eigen::VectorXd previous_r_, previous_xt_;  // r and x~ of the step's last iteration
  // Secant pairs (dr, dx~), newest first: this step's, then earlier steps' (newest first).
  std::deque<Eigen::VectorXd> v_step_, w_step_;
  std::deque<std::deque<Eigen::VectorXd>> v_old_, w_old_;

 private:
  Columns qr2_columns(const std::vector<const Eigen::VectorXd*>& v, const std::vector<const Eigen::VectorXd*>& w,
                      Eigen::Index n) const;
  Columns qr1_columns(std::vector<const Eigen::VectorXd*> v, std::vector<const Eigen::VectorXd*> w,
                      Eigen::Index n) const;
  bool qr3_insert(Eigen::Index n);  // the new column into columns_; false: qr2 is needed
  void update_preconditioner(const Eigen::VectorXd& r);

  Columns columns_;             // the last filtered_columns() result (qr3 updates it)
  bool columns_valid_ = false;  // columns_ belongs to this step's columns but the newest
  // residual-sum preconditioner: the weights of the force components (x, y) and this step's
  // sums of their shares of the residual norm.
  Eigen::Vector2d weights_ = Eigen::Vector2d::Ones(), shares_ = Eigen::Vector2d::Zero();
  bool weights_set_ = false, weights_changed_ = false;
};

}  // namespace fsi::coupling
