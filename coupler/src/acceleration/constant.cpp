// Constant relaxation (the seed paper): F^(k+1) = F^(k) + beta r_k.
#include "schemes.hpp"

namespace fsi::coupling {
namespace {

class ConstantRelaxation : public Accelerator {
 public:
  using Accelerator::Accelerator;
  Eigen::VectorXd update(const Eigen::VectorXd& x, const Eigen::VectorXd& r) override {
    ++k_;
    last_columns_ = 0;
    last_omega_ = settings_.beta;
    return x + last_omega_ * r;
  }
};

}  // namespace

std::unique_ptr<Accelerator> make_constant_relaxation(const CouplingSettings& settings) {
  return std::make_unique<ConstantRelaxation>(settings);
}

}  // namespace fsi::coupling
