// IQN-IMVJ, the interface quasi-Newton method with the multi-vector Jacobian (Lindner, Mehl,
// Scheufele & Uekermann 2015; preCICE's IQN-IMVJ). The inverse Jacobian of the residual
// (dx~ = J dr) of the earlier steps, J_prev, is the prior of this step's least-squares update:
//   J = J_prev + (W - J_prev V) Z,   Z = (V^T P^2 V)^-1 V^T P^2 = R^-1 Q^T P,
//   F^(k+1) = x~_k - J r_k,
// with V, W this step's secant pairs (and those of `reuse_steps` earlier steps, usually
// none: J_prev carries them). The very first update, with neither J_prev nor a pair, is the
// constant relaxation beta. Accepted, the step's J becomes the next step's J_prev:
//   restart none    J_prev stored dense (n x n);
//   restart rs-*    J_prev = [base] + sum over the steps since the last restart of their
//                   updates (W - J_prev V) Z, each kept as its two factors; after chunk_size
//                   steps a restart: rs-0 drops them, rs-ls replaces them by the least-squares
//                   Jacobian W Z of the last restart_reuse_steps steps' pairs, rs-svd folds them
//                   into a truncated SVD psi diag(sigma) phi^T of the accumulated J (singular
//                   values below truncation x the largest dropped).
#include <Eigen/Dense>

#include "quasi_newton.hpp"
#include "schemes.hpp"

namespace fsi::coupling {
namespace {

class IqnImvj : public QuasiNewton {
 public:
  explicit IqnImvj(const CouplingSettings& settings) : QuasiNewton(settings) {}
  void end_step() override;
  void save(StateArchive& state, const std::string& prefix) const override;
  void load(const StateArchive& state, const std::string& prefix) override;

 protected:
  const char* scheme() const override { return "iqn-imvj"; }
  Eigen::VectorXd quasi_newton_update(const Eigen::VectorXd& x, const Eigen::VectorXd& r,
                                      const Eigen::VectorXd& xt) override;

 private:
  struct Factors {  // a Jacobian update wtil z (n x m times m x n)
    Eigen::MatrixXd wtil, z;
  };
  bool has_prior() const { return jacobian_.size() > 0 || !chunk_.empty() || sigma_.size() > 0; }
  Eigen::MatrixXd apply_prior(const Eigen::MatrixXd& y) const;  // J_prev y
  void restart();
  void svd_add(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b);  // psi sigma phi^T += a b^T
  static Eigen::MatrixXd columns_of(const std::vector<const Eigen::VectorXd*>& cols, Eigen::Index m);

  Eigen::MatrixXd jacobian_;    // restart none: J_prev (empty = 0)
  std::vector<Factors> chunk_;  // restart modes: the updates since the last restart
  int steps_in_chunk_ = 0;
  std::deque<std::deque<Eigen::VectorXd>> v_restart_, w_restart_;  // rs-ls: the last steps' pairs
  Eigen::MatrixXd psi_, phi_;                                      // rs-svd: J_svd = psi diag(sigma) phi^T
  Eigen::VectorXd sigma_;
  Factors last_;  // the step's update at its last iteration
  bool last_valid_ = false;
};

Eigen::MatrixXd IqnImvj::columns_of(const std::vector<const Eigen::VectorXd*>& cols, Eigen::Index m) {
  Eigen::MatrixXd out(cols.front()->size(), m);
  for (Eigen::Index j = 0; j < m; ++j) out.col(j) = *cols[j];
  return out;
}

Eigen::MatrixXd IqnImvj::apply_prior(const Eigen::MatrixXd& y) const {
  Eigen::MatrixXd out =
      jacobian_.size() > 0 ? Eigen::MatrixXd(jacobian_ * y) : Eigen::MatrixXd::Zero(y.rows(), y.cols());
  for (const auto& f : chunk_) out += f.wtil * (f.z * y);
  if (sigma_.size() > 0) out += psi_ * (sigma_.asDiagonal() * (phi_.transpose() * y));
  return out;
}

Eigen::VectorXd IqnImvj::quasi_newton_update(const Eigen::VectorXd& x, const Eigen::VectorXd& r,
                                             const Eigen::VectorXd& xt) {
  const Columns& c = filtered_columns(r.size());
  const Eigen::Index m = c.m;
  last_columns_ = static_cast<int>(m);
  last_valid_ = false;
  if (m == 0 && !has_prior()) {
    last_omega_ = settings_.beta;
    return x + settings_.beta * r;
  }
  last_omega_ = 0;
  Eigen::VectorXd next = xt;
  if (has_prior()) next -= apply_prior(r);
  if (m == 0) return next;
  const Eigen::MatrixXd v = columns_of(c.v, m);
  Eigen::MatrixXd wtil = columns_of(c.w, m);
  if (has_prior()) wtil -= apply_prior(v);
  next += wtil * solve(c, -r);
  last_ = {std::move(wtil), pseudo_inverse(c)};
  last_valid_ = true;
  return next;
}

void IqnImvj::end_step() {
  QuasiNewton::end_step();
  if (settings_.imvj_restart == ImvjRestart::None) {
    if (last_valid_) {
      if (jacobian_.size() == 0)
        jacobian_ = last_.wtil * last_.z;
      else
        jacobian_.noalias() += last_.wtil * last_.z;
    }
  } else {
    if (last_valid_) chunk_.push_back(last_);
    if (settings_.imvj_restart == ImvjRestart::LeastSquares && !v_step_.empty()) {
      v_restart_.push_front(v_step_);
      w_restart_.push_front(w_step_);
      while (static_cast<int>(v_restart_.size()) > settings_.imvj_restart_reuse_steps) {
        v_restart_.pop_back();
        w_restart_.pop_back();
      }
    }
    if (++steps_in_chunk_ >= settings_.imvj_chunk_size) restart();
  }
  last_valid_ = false;
}

void IqnImvj::restart() {
  steps_in_chunk_ = 0;
  if (settings_.imvj_restart == ImvjRestart::Svd) {
    for (const auto& f : chunk_) svd_add(f.wtil, f.z.transpose());
    chunk_.clear();
    return;
  }
  chunk_.clear();
  if (settings_.imvj_restart != ImvjRestart::LeastSquares) return;
  std::vector<const Eigen::VectorXd*> v, w;
  for (std::size_t s = 0; s < v_restart_.size(); ++s)
    for (std::size_t i = 0; i < v_restart_[s].size(); ++i)
      v.push_back(&v_restart_[s][i]), w.push_back(&w_restart_[s][i]);
  if (v.empty()) return;
  const Columns c = filter_columns(v, w, v.front()->size());
  if (c.m > 0) chunk_.push_back({columns_of(c.w, c.m), pseudo_inverse(c)});
}

// Brand's update of a thin SVD by a low-rank term, then the truncation.
void IqnImvj::svd_add(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  const Eigen::Index n = a.rows(), k = sigma_.size(), m = a.cols(), mq = std::min(n, m);
  auto orthogonal = [&](const Eigen::MatrixXd& basis, const Eigen::MatrixXd& x, Eigen::MatrixXd& coeff,
                        Eigen::MatrixXd& q, Eigen::MatrixXd& rx) {
    coeff = k > 0 ? Eigen::MatrixXd(basis.transpose() * x) : Eigen::MatrixXd(0, m);
    const Eigen::MatrixXd rest = k > 0 ? Eigen::MatrixXd(x - basis * coeff) : x;
    Eigen::HouseholderQR<Eigen::MatrixXd> qr(rest);
    q = qr.householderQ() * Eigen::MatrixXd::Identity(n, mq);
    rx = qr.matrixQR().topRows(mq).triangularView<Eigen::Upper>();
  };
  Eigen::MatrixXd at, p, ra, bt, q, rb;
  orthogonal(psi_, a, at, p, ra);
  orthogonal(phi_, b, bt, q, rb);
  Eigen::MatrixXd ka(k + mq, m), kb(k + mq, m);
  ka << at, ra;
  kb << bt, rb;
  Eigen::MatrixXd kk = ka * kb.transpose();
  kk.topLeftCorner(k, k).diagonal() += sigma_;
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(kk, Eigen::ComputeThinU | Eigen::ComputeThinV);
  Eigen::MatrixXd left(n, k + mq), right(n, k + mq);
  if (k > 0) left.leftCols(k) = psi_, right.leftCols(k) = phi_;
  left.rightCols(mq) = p;
  right.rightCols(mq) = q;
  Eigen::Index rank = 0;
  const Eigen::VectorXd& s = svd.singularValues();
  while (rank < s.size() && rank < n && s(rank) > 0 && s(rank) >= settings_.imvj_truncation * s(0)) ++rank;
  psi_ = left * svd.matrixU().leftCols(rank);
  phi_ = right * svd.matrixV().leftCols(rank);
  sigma_ = s.head(rank);
}

void IqnImvj::save(StateArchive& state, const std::string& prefix) const {
  QuasiNewton::save(state, prefix);
  const std::string p = prefix + "imvj.";
  if (jacobian_.size() > 0) state.put_matrix(p + "jacobian", jacobian_);
  state.put(p + "chunk", static_cast<std::int64_t>(chunk_.size()));
  for (std::size_t i = 0; i < chunk_.size(); ++i) {
    state.put_matrix(p + "chunk" + std::to_string(i) + ".wtil", chunk_[i].wtil);
    state.put_matrix(p + "chunk" + std::to_string(i) + ".z", chunk_[i].z);
  }
  state.put(p + "steps_in_chunk", static_cast<std::int64_t>(steps_in_chunk_));
  state.put(p + "restart_steps", static_cast<std::int64_t>(v_restart_.size()));
  for (std::size_t s = 0; s < v_restart_.size(); ++s) {
    const std::string q = p + "restart" + std::to_string(s) + ".";
    state.put(q + "columns", static_cast<std::int64_t>(v_restart_[s].size()));
    for (std::size_t i = 0; i < v_restart_[s].size(); ++i) {
      state.put(q + "v" + std::to_string(i), v_restart_[s][i]);
      state.put(q + "w" + std::to_string(i), w_restart_[s][i]);
    }
  }
  if (sigma_.size() > 0) {
    state.put_matrix(p + "psi", psi_);
    state.put_matrix(p + "phi", phi_);
    state.put(p + "sigma", sigma_);
  }
}

void IqnImvj::load(const StateArchive& state, const std::string& prefix) {
  QuasiNewton::load(state, prefix);
  jacobian_.resize(0, 0);
  chunk_.clear();
  steps_in_chunk_ = 0;
  v_restart_.clear();
  w_restart_.clear();
  psi_.resize(0, 0);
  phi_.resize(0, 0);
  sigma_.resize(0);
  last_valid_ = false;
  if (!state.has(prefix + "scheme") || state.text(prefix + "scheme") != scheme()) return;
  const std::string p = prefix + "imvj.";
  const bool restarts = settings_.imvj_restart != ImvjRestart::None;  // a fork may change the mode
  if (!restarts && state.has(p + "jacobian")) jacobian_ = state.matrix(p + "jacobian");
  if (!restarts) return;
  const auto chunk = state.integer(p + "chunk");
  for (std::int64_t i = 0; i < chunk; ++i)
    chunk_.push_back({state.matrix(p + "chunk" + std::to_string(i) + ".wtil"),
                      state.matrix(p + "chunk" + std::to_string(i) + ".z")});
  steps_in_chunk_ = static_cast<int>(state.integer(p + "steps_in_chunk"));
  const auto steps = state.integer(p + "restart_steps");
  for (std::int64_t s = 0; s < steps; ++s) {
    const std::string q = p + "restart" + std::to_string(s) + ".";
    std::deque<Eigen::VectorXd> v, w;
    for (std::int64_t i = 0; i < state.integer(q + "columns"); ++i) {
      v.push_back(state.vector(q + "v" + std::to_string(i)));
      w.push_back(state.vector(q + "w" + std::to_string(i)));
    }
    v_restart_.push_back(std::move(v));
    w_restart_.push_back(std::move(w));
  }
  if (state.has(p + "sigma")) {
    psi_ = state.matrix(p + "psi");
    phi_ = state.matrix(p + "phi");
    sigma_ = state.vector(p + "sigma");
  }
}

}  // namespace

std::unique_ptr<Accelerator> make_iqn_imvj(const CouplingSettings& settings) {
  return std::make_unique<IqnImvj>(settings);
}

}  // namespace fsi::coupling
