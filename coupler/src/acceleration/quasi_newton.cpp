#include "quasi_newton.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

namespace fsi::coupling {

void QuasiNewton::begin_step() {
  Accelerator::begin_step();
  previous_r_.resize(0);
  previous_xt_.resize(0);
  v_step_.clear();
  w_step_.clear();
  columns_valid_ = false;
  shares_.setZero();
}

Eigen::VectorXd QuasiNewton::update(const Eigen::VectorXd& x, const Eigen::VectorXd& r) {
  ++k_;
  last_columns_ = 0;
  const Eigen::VectorXd xt = x + r;
  if (previous_r_.size() == r.size()) {
    v_step_.push_front(r - previous_r_);
    w_step_.push_front(xt - previous_xt_);
  }
  previous_r_ = r;
  previous_xt_ = xt;
  if (settings_.iqn_preconditioner == Preconditioner::ResidualSum) update_preconditioner(r);
  return quasi_newton_update(x, r, xt);
}

void QuasiNewton::end_step() {
  if (settings_.reuse_steps <= 0) return;
  if (!v_step_.empty()) {
    v_old_.push_front(v_step_);
    w_old_.push_front(w_step_);
  }
  while (static_cast<int>(v_old_.size()) > settings_.reuse_steps) {
    v_old_.pop_back();
    w_old_.pop_back();
  }
}

void QuasiNewton::save(StateArchive& state, const std::string& prefix) const {
  Accelerator::save(state, prefix);
  state.put(prefix + "reused_steps", static_cast<std::int64_t>(v_old_.size()));
  for (std::size_t s = 0; s < v_old_.size(); ++s) {
    const std::string p = prefix + "step" + std::to_string(s) + ".";
    state.put(p + "columns", static_cast<std::int64_t>(v_old_[s].size()));
    for (std::size_t i = 0; i < v_old_[s].size(); ++i) {
      state.put(p + "v" + std::to_string(i), v_old_[s][i]);
      state.put(p + "w" + std::to_string(i), w_old_[s][i]);
    }
  }
  state.put(prefix + "scheme", std::string(scheme()));
  if (settings_.iqn_preconditioner == Preconditioner::ResidualSum && weights_set_)
    state.put(prefix + "preconditioner.weights", Eigen::VectorXd(weights_));
}

// A checkpoint of another scheme (a fork into this one) gives only the last factor; earlier
// checkpoints name no scheme and were IQN-ILS's or had no secant pairs. Reused steps beyond
// this run's reuse_steps are dropped.
void QuasiNewton::load(const StateArchive& state, const std::string& prefix) {
  Accelerator::load(state, prefix);
  v_old_.clear();
  w_old_.clear();
  weights_.setOnes();
  weights_set_ = false;
  if (state.has(prefix + "scheme") && state.text(prefix + "scheme") != scheme()) return;
  const auto steps = state.has(prefix + "reused_steps") ? state.integer(prefix + "reused_steps") : 0;
  for (std::int64_t s = 0; s < std::min<std::int64_t>(steps, settings_.reuse_steps); ++s) {
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
  if (state.has(prefix + "preconditioner.weights")) {
    weights_ = state.vector(prefix + "preconditioner.weights", 2);
    weights_set_ = true;
  }
}

// ---- The residual-sum preconditioner (two blocks: the x and y components of the force).

void QuasiNewton::update_preconditioner(const Eigen::VectorXd& r) {
  Eigen::Vector2d norms = Eigen::Vector2d::Zero();
  for (Eigen::Index i = 0; i < r.size(); ++i) norms(i % 2) += r(i) * r(i);
  norms = norms.cwiseSqrt();
  const double total = norms.norm();
  if (!(total > 0) || !std::isfinite(total)) return;
  shares_ += norms / total;
  Eigen::Vector2d next = weights_;
  for (int b = 0; b < 2; ++b)
    if (shares_(b) > 0) next(b) = 1.0 / shares_(b);
  bool jump = !weights_set_;
  for (int b = 0; b < 2; ++b) jump = jump || next(b) > 10 * weights_(b) || 10 * next(b) < weights_(b);
  if (!jump) return;
  weights_ = next;
  weights_set_ = true;
  weights_changed_ = true;
}

Eigen::VectorXd QuasiNewton::scaled(const Eigen::VectorXd& y) const {
  if (settings_.iqn_preconditioner == Preconditioner::None) return y;
  Eigen::VectorXd out = y;
  for (Eigen::Index i = 0; i < out.size(); ++i) out(i) *= weights_(i % 2);
  return out;
}

// ---- The filters.

const QuasiNewton::Columns& QuasiNewton::filtered_columns(Eigen::Index n) {
  const bool new_column = k_ > 1 && !v_step_.empty();
  if (settings_.iqn_filter_type == QrFilter::Qr3 && new_column && qr3_insert(n)) return columns_;
  std::vector<const Eigen::VectorXd*> v, w;
  for (std::size_t i = 0; i < v_step_.size(); ++i) v.push_back(&v_step_[i]), w.push_back(&w_step_[i]);
  for (std::size_t s = 0; s < v_old_.size(); ++s)
    for (std::size_t i = 0; i < v_old_[s].size(); ++i) v.push_back(&v_old_[s][i]), w.push_back(&w_old_[s][i]);
  columns_ = filter_columns(v, w, n);
  columns_valid_ = true;
  weights_changed_ = false;
  return columns_;
}

QuasiNewton::Columns QuasiNewton::filter_columns(const std::vector<const Eigen::VectorXd*>& v,
                                                 const std::vector<const Eigen::VectorXd*>& w, Eigen::Index n) const {
  return settings_.iqn_filter_type == QrFilter::Qr1 ? qr1_columns(v, w, n) : qr2_columns(v, w, n);
}

// Modified Gram-Schmidt, newest first; a column whose remainder is below `iqn_filter` times
// its own norm is (nearly) dependent on newer information and is dropped.
QuasiNewton::Columns QuasiNewton::qr2_columns(const std::vector<const Eigen::VectorXd*>& v,
                                              const std::vector<const Eigen::VectorXd*>& w, Eigen::Index n) const {
  const Eigen::Index max_columns = std::min<Eigen::Index>(static_cast<Eigen::Index>(v.size()), n);
  Columns c;
  c.q.resize(n, max_columns);
  c.r = Eigen::MatrixXd::Zero(max_columns, max_columns);
  Eigen::Index& m = c.m;
  for (std::size_t j = 0; j < v.size() && m < max_columns; ++j) {
    Eigen::VectorXd col = scaled(*v[j]);
    const double norm0 = col.norm();
    if (!(norm0 > 0) || !std::isfinite(norm0)) continue;
    Eigen::VectorXd coeff(m);
    for (Eigen::Index i = 0; i < m; ++i) {
      coeff(i) = c.q.col(i).dot(col);
      col -= coeff(i) * c.q.col(i);
    }
    const double norm = col.norm();
    if (norm < settings_.iqn_filter * norm0) continue;
    c.r.col(m).head(m) = coeff;
    c.r(m, m) = norm;
    c.q.col(m) = col / norm;
    c.v.push_back(v[j]);
    c.w.push_back(w[j]);
    ++m;
  }
  return c;
}

// The QR decomposition of all columns (newest first, at most n), then, while there are two
// or more, the first column with |R_ii| < eps ||R||_F is dropped and the rest decomposed again.
QuasiNewton::Columns QuasiNewton::qr1_columns(std::vector<const Eigen::VectorXd*> v,
                                              std::vector<const Eigen::VectorXd*> w, Eigen::Index n) const {
  while (true) {
    Columns c;
    const Eigen::Index max_columns = std::min<Eigen::Index>(static_cast<Eigen::Index>(v.size()), n);
    c.q.resize(n, max_columns);
    c.r = Eigen::MatrixXd::Zero(max_columns, max_columns);
    for (std::size_t j = 0; j < v.size() && c.m < max_columns; ++j) {
      Eigen::VectorXd col = scaled(*v[j]);
      const double norm0 = col.norm();
      if (!(norm0 > 0) || !std::isfinite(norm0)) continue;
      for (int pass = 0; pass < 2; ++pass)  // twice is enough (Kahan, Parlett)
        for (Eigen::Index i = 0; i < c.m; ++i) {
          const double a = c.q.col(i).dot(col);
          c.r(i, c.m) += a;
          col -= a * c.q.col(i);
        }
      const double norm = col.norm();
      if (!(norm > 0)) continue;
      c.r(c.m, c.m) = norm;
      c.q.col(c.m) = col / norm;
      c.v.push_back(v[j]);
      c.w.push_back(w[j]);
      ++c.m;
    }
    if (c.m < 2) return c;
    const double frobenius = c.r.topLeftCorner(c.m, c.m).norm();
    Eigen::Index drop = -1;
    for (Eigen::Index i = 0; i < c.m && drop < 0; ++i)
      if (std::abs(c.r(i, i)) < settings_.iqn_filter * frobenius) drop = i;
    if (drop < 0) return c;
    v = c.v, w = c.w;
    v.erase(v.begin() + drop);
    w.erase(w.begin() + drop);
  }
}

// QR3: the newest column inserted in front of the last decomposition (Givens rotations from
// the bottom restore R's triangle); the result is qr2's unless a column's remainder fails
// qr2's test, which is then run.
bool QuasiNewton::qr3_insert(Eigen::Index n) {
  if (!columns_valid_ || weights_changed_) return false;
  Columns& c = columns_;
  Eigen::Index m = c.m;
  if (m + 1 > n) --m;  // at most n columns: the oldest kept one goes
  const Eigen::VectorXd v0 = scaled(v_step_.front());
  const double norm0 = v0.norm();
  if (!(norm0 > 0) || !std::isfinite(norm0)) return false;
  Eigen::VectorXd col = v0, u = Eigen::VectorXd::Zero(m);
  for (int pass = 0; pass < 2; ++pass) {
    const Eigen::VectorXd a = c.q.leftCols(m).transpose() * col;
    col -= c.q.leftCols(m) * a;
    u += a;
  }
  const double rho = col.norm();
  if (!(rho > 1e-14 * norm0)) return false;
  Eigen::MatrixXd h = Eigen::MatrixXd::Zero(m + 1, m + 1), q(n, m + 1);
  h.col(0).head(m) = u;
  h(m, 0) = rho;
  h.block(0, 1, m, m) = c.r.topLeftCorner(m, m);
  q.leftCols(m) = c.q.leftCols(m);
  q.col(m) = col / rho;
  for (Eigen::Index l = m - 1; l >= 0; --l) {
    const double a = h(l, 0), b = h(l + 1, 0), g = std::hypot(a, b);
    if (!(g > 0)) continue;
    const double cs = a / g, sn = b / g;
    for (Eigen::Index j = 0; j <= m; ++j) {
      const double x = h(l, j), y = h(l + 1, j);
      h(l, j) = cs * x + sn * y;
      h(l + 1, j) = -sn * x + cs * y;
    }
    const Eigen::VectorXd ql = q.col(l), ql1 = q.col(l + 1);
    q.col(l) = cs * ql + sn * ql1;
    q.col(l + 1) = -sn * ql + cs * ql1;
  }
  std::vector<const Eigen::VectorXd*> v{&v_step_.front()}, w{&w_step_.front()};
  v.insert(v.end(), c.v.begin(), c.v.begin() + m);
  w.insert(w.end(), c.w.begin(), c.w.begin() + m);
  for (Eigen::Index i = 1; i <= m; ++i)
    if (std::abs(h(i, i)) < settings_.iqn_filter * scaled(*v[i]).norm()) return false;
  c.q = std::move(q);
  c.r = std::move(h);
  c.v = std::move(v);
  c.w = std::move(w);
  c.m = m + 1;
  return true;
}

// ---- The least-squares solution.

Eigen::VectorXd QuasiNewton::solve(const Columns& c, const Eigen::VectorXd& y) const {
  const Eigen::Index m = c.m;
  const Eigen::VectorXd rhs = c.q.leftCols(m).transpose() * scaled(y);
  return c.r.topLeftCorner(m, m).triangularView<Eigen::Upper>().solve(rhs);
}

Eigen::MatrixXd QuasiNewton::pseudo_inverse(const Columns& c) const {
  const Eigen::Index m = c.m;
  Eigen::MatrixXd qt = c.q.leftCols(m).transpose();
  if (settings_.iqn_preconditioner != Preconditioner::None)
    for (Eigen::Index i = 0; i < qt.cols(); ++i) qt.col(i) *= weights_(i % 2);
  return c.r.topLeftCorner(m, m).triangularView<Eigen::Upper>().solve(qt);
}

}  // namespace fsi::coupling
