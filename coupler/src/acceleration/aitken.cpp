// Aitken's dynamic relaxation (Kuttler & Wall 2008): each step starts with beta, then
//   omega_k = -omega_{k-1} r_{k-1}.(r_k - r_{k-1}) / |r_k - r_{k-1}|^2,
// clamped to [-1, 1] (beta again when it would vanish).
#include <algorithm>
#include <cmath>

#include "schemes.hpp"

namespace fsi::coupling {
namespace {

class Aitken : public Accelerator {
 public:
  using Accelerator::Accelerator;
  void begin_step() override {
    Accelerator::begin_step();
    previous_r_.resize(0);
  }
  Eigen::VectorXd update(const Eigen::VectorXd& x, const Eigen::VectorXd& r) override {
    ++k_;
    last_columns_ = 0;
    const double beta = settings_.beta;
    double omega = beta;
    if (k_ > 1 && previous_r_.size() == r.size()) {
      const Eigen::VectorXd dr = r - previous_r_;
      const double dr2 = dr.squaredNorm();
      if (dr2 > 0) omega = std::clamp(-last_omega_ * previous_r_.dot(dr) / dr2, -1.0, 1.0);
      if (std::abs(omega) < 1e-6) omega = beta;
    }
    previous_r_ = r;
    last_omega_ = omega;
    return x + omega * r;
  }

 private:
  Eigen::VectorXd previous_r_;  // r of the step's last iteration
};

}  // namespace

std::unique_ptr<Accelerator> make_aitken(const CouplingSettings& settings) {
  return std::make_unique<Aitken>(settings);
}

}  // namespace fsi::coupling
