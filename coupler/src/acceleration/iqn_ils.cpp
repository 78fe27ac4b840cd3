// IQN-ILS (Degroote, Bathe & Vierendeels 2009): with V = [dr_i], W = [dx~_i] (differences of
// consecutive iterations), the inverse Jacobian of the residual is modelled so that dx~ = W c
// for the c minimising |V c + r_k|: F^(k+1) = x~_k + W c, x~_k = F^(k) + r_k. Without a
// secant pair (a step's first iteration and nothing reused) the update is the constant
// relaxation beta.
#include "quasi_newton.hpp"
#include "schemes.hpp"

namespace fsi::coupling {
namespace {

class IqnIls : public QuasiNewton {
 public:
  explicit IqnIls(const CouplingSettings& settings) : QuasiNewton(settings) {}

 protected:
  const char* scheme() const override { return "iqn-ils"; }
  Eigen::VectorXd quasi_newton_update(const Eigen::VectorXd& x, const Eigen::VectorXd& r,
                                      const Eigen::VectorXd& xt) override {
    const Columns& c = filtered_columns(r.size());
    const Eigen::Index m = c.m;
    last_columns_ = static_cast<int>(m);
    if (m == 0) {
      last_omega_ = settings_.beta;
      return x + settings_.beta * r;
    }
    // min |P (V c + r)| = min |Q R c + P r|  =>  R c = -Q^T P r
    const Eigen::VectorXd coeff = solve(c, -r);
    Eigen::VectorXd next = xt;
    for (Eigen::Index j = 0; j < m; ++j) next += coeff(j) * *c.w[j];
    last_omega_ = 0;
    return next;
  }
};

}  // namespace

std::unique_ptr<Accelerator> make_iqn_ils(const CouplingSettings& settings) {
  return std::make_unique<IqnIls>(settings);
}

}  // namespace fsi::coupling
