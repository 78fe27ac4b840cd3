#include "fsi/coupling/acceleration.hpp"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>

namespace fsi::coupling {

void InterfaceAccelerator::begin_step() {
  k_ = 0;
  previous_r_.resize(0);
  previous_xt_.resize(0);
  v_step_.clear();
  w_step_.clear();
}

void InterfaceAccelerator::end_step() {
  if (settings_.acceleration != Acceleration::IqnIls || settings_.reuse_steps <= 0) return;
  if (!v_step_.empty()) {
    v_old_.push_front(v_step_);
    w_old_.push_front(w_step_);
  }
  while (static_cast<int>(v_old_.size()) > settings_.reuse_steps) {
    v_old_.pop_back();
    w_old_.pop_back();
  }
}

void InterfaceAccelerator::save(StateArchive& state, const std::string& prefix) const {
  state.put(prefix + "last_omega", last_omega_);
  state.put(prefix + "reused_steps", static_cast<std::int64_t>(v_old_.size()));
  for (std::size_t s = 0; s < v_old_.size(); ++s) {
    const std::string p = prefix + "step" + std::to_string(s) + ".";
    state.put(p + "columns", static_cast<std::int64_t>(v_old_[s].size()));
    for (std::size_t i = 0; i < v_old_[s].size(); ++i) {
      state.put(p + "v" + std::to_string(i), v_old_[s][i]);
      state.put(p + "w" + std::to_string(i), w_old_[s][i]);
    }
  }
}

void InterfaceAccelerator::load(const StateArchive& state, const std::string& prefix) {
  begin_step();
  last_omega_ = state.real(prefix + "last_omega");
  v_old_.clear();
  w_old_.clear();
  const auto steps = state.integer(prefix + "reused_steps");
  for (std::int64_t s = 0; s < steps; ++s) {
    const std::string p = prefix + "step" + std::to_string(s) + ".";
    std::deque<Eigen::VectorXd> v, w;
    const auto columns = state.integer(p + "columns");
    for (std::int64_t i = 0; i < columns; ++i) {
      v.push_back(state.vector(p + "v" + std::to_string(i)));
      w.push_back(state.vector(p + "w" + std::to_string(i)));
    }
    v_old_.push_back(std::move(v));
    w_old_.push_back(std::move(w));
  }
}

Eigen::VectorXd InterfaceAccelerator::update(const Eigen::VectorXd& x, const Eigen::VectorXd& r) {
  ++k_;
  last_columns_ = 0;
  const double beta = settings_.relaxation;
  if (settings_.acceleration == Acceleration::IqnIls) return quasi_newton(x, r);
  double omega = beta;
  if (settings_.acceleration == Acceleration::Aitken && k_ > 1 && previous_r_.size() == r.size()) {
    // omega_k = -omega_{k-1} r_{k-1}.(r_k - r_{k-1}) / |r_k - r_{k-1}|^2
    const Eigen::VectorXd dr = r - previous_r_;
    const double dr2 = dr.squaredNorm();
    if (dr2 > 0) omega = std::clamp(-last_omega_ * previous_r_.dot(dr) / dr2, -1.0, 1.0);
    if (std::abs(omega) < 1e-6) omega = beta;
  }
  previous_r_ = r;
  last_omega_ = omega;
  return x + omega * r;
}

// IQN-ILS: with V = [dr_i], W = [dx~_i] (differences of consecutive iterations), the
// inverse Jacobian of the residual is modelled so that dx~ = W c for the c minimising
// |V c + r_k|: F^(k+1) = x~_k + W c, x~_k = F^(k) + r_k. Columns are orthogonalised newest
// first (modified Gram-Schmidt); one whose remainder is below `filter` times its own norm
// is (nearly) linearly dependent on newer information and is dropped (QR1 filter).
Eigen::VectorXd InterfaceAccelerator::quasi_newton(const Eigen::VectorXd& x, const Eigen::VectorXd& r) {
  const Eigen::VectorXd xt = x + r;
  if (previous_r_.size() == r.size()) {
    v_step_.push_front(r - previous_r_);
    w_step_.push_front(xt - previous_xt_);
  }
  previous_r_ = r;
  previous_xt_ = xt;

  std::vector<const Eigen::VectorXd*> v, w;
  for (std::size_t i = 0; i < v_step_.size(); ++i) v.push_back(&v_step_[i]), w.push_back(&w_step_[i]);
  for (std::size_t s = 0; s < v_old_.size(); ++s)
    for (std::size_t i = 0; i < v_old_[s].size(); ++i) v.push_back(&v_old_[s][i]), w.push_back(&w_old_[s][i]);
  const Eigen::Index n = r.size();
  const Eigen::Index max_columns = std::min<Eigen::Index>(static_cast<Eigen::Index>(v.size()), n);
  Eigen::MatrixXd q(n, max_columns), rr = Eigen::MatrixXd::Zero(max_columns, max_columns);
  std::vector<const Eigen::VectorXd*> kept_w;
  Eigen::Index m = 0;
  for (std::size_t j = 0; j < v.size() && m < max_columns; ++j) {
    Eigen::VectorXd col = *v[j];
    const double norm0 = col.norm();
    if (!(norm0 > 0) || !std::isfinite(norm0)) continue;
    Eigen::VectorXd coeff(m);
    for (Eigen::Index i = 0; i < m; ++i) {
      coeff(i) = q.col(i).dot(col);
      col -= coeff(i) * q.col(i);
    }
    const double norm = col.norm();
    if (norm < settings_.iqn_filter * norm0) continue;
    rr.col(m).head(m) = coeff;
    rr(m, m) = norm;
    q.col(m) = col / norm;
    kept_w.push_back(w[j]);
    ++m;
  }
  last_columns_ = static_cast<int>(m);
  if (m == 0) {
    last_omega_ = settings_.relaxation;
    return x + settings_.relaxation * r;
  }
  // min |Q R c + r|  =>  R c = -Q^T r
  const Eigen::VectorXd rhs = -(q.leftCols(m).transpose() * r);
  const Eigen::VectorXd c = rr.topLeftCorner(m, m).triangularView<Eigen::Upper>().solve(rhs);
  Eigen::VectorXd next = xt;
  for (Eigen::Index j = 0; j < m; ++j) next += c(j) * *kept_w[j];
  last_omega_ = 0;
  return next;
}

}  // namespace fsi::coupling
