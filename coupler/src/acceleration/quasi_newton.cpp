#include "quasi_newton.hpp"

#include <algorithm>
#include <cmath>

namespace fsi::coupling {

void QuasiNewton::begin_step() {
  Accelerator::begin_step();
  previous_r_.resize(0);
  previous_xt_.resize(0);
  v_step_.clear();
  w_step_.clear();
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
}

void QuasiNewton::load(const StateArchive& state, const std::string& prefix) {
  Accelerator::load(state, prefix);
  v_old_.clear();
  w_old_.clear();
  const auto steps = state.has(prefix + "reused_steps") ? state.integer(prefix + "reused_steps") : 0;
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

QuasiNewton::Columns QuasiNewton::filtered_columns(Eigen::Index n) const {
  std::vector<const Eigen::VectorXd*> v, w;
  for (std::size_t i = 0; i < v_step_.size(); ++i) v.push_back(&v_step_[i]), w.push_back(&w_step_[i]);
  for (std::size_t s = 0; s < v_old_.size(); ++s)
    for (std::size_t i = 0; i < v_old_[s].size(); ++i) v.push_back(&v_old_[s][i]), w.push_back(&w_old_[s][i]);
  const Eigen::Index max_columns = std::min<Eigen::Index>(static_cast<Eigen::Index>(v.size()), n);
  Columns c;
  c.q.resize(n, max_columns);
  c.r = Eigen::MatrixXd::Zero(max_columns, max_columns);
  Eigen::Index& m = c.m;
  for (std::size_t j = 0; j < v.size() && m < max_columns; ++j) {
    Eigen::VectorXd col = *v[j];
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

}  // namespace fsi::coupling
