#pragma once
// How the coupler's interface fixed-point iteration F^(k+1) = G(F^(k)) is updated from the
// residual r_k = -F*(F^(k)) - F^(k): one class per scheme behind the interface Accelerator,
// made by make_accelerator() from the scheme's name in the registry (src/acceleration/registry.cpp):
//  - constant: F^(k+1) = F^(k) + beta r_k (the seed paper);
//  - aitken:   omega_k from the last two residuals (Kuttler & Wall 2008), starting at beta;
//  - iqn-ils:  interface quasi-Newton with a least-squares model of the inverse Jacobian
//              (Degroote, Bathe & Vierendeels 2009), optionally reusing the secant pairs of
//              the last `reuse_steps` time steps. Its first iteration, with no secant pair
//              yet, is the constant relaxation beta.
//  - iqn-imvj: interface quasi-Newton with the multi-vector Jacobian (Lindner, Mehl, Scheufele
//              & Uekermann 2015; preCICE's IQN-IMVJ): the inverse Jacobian of earlier steps
//              is the prior of this step's least-squares update, without or with restarts.
// The quasi-Newton schemes' filters (qr1, qr2, qr3) and residual-sum preconditioner: settings.hpp.
// A new scheme is one file with its class and one line in the registry; its name becomes a
// value of coupling.acceleration by itself (coupling_keys.cpp takes the registry's names), and
// options of its own, if any, are declared in coupler/src/coupling_keys.cpp.
// Pure linear algebra: no knowledge of solvers, messages or time.
#include <Eigen/Core>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "fsi/common/state.hpp"
#include "fsi/coupling/settings.hpp"

namespace fsi::coupling {

class Accelerator {
 public:
  explicit Accelerator(const CouplingSettings& settings) : settings_(settings) {}
  virtual ~Accelerator() = default;
  // Called at each step's first iteration.
  virtual void begin_step();
  // x = F^(k), r = G(F^(k)) - F^(k); returns F^(k+1).
  virtual Eigen::VectorXd update(const Eigen::VectorXd& x, const Eigen::VectorXd& r) = 0;
  // Called when the step is accepted (a quasi-Newton scheme keeps what it learnt).
  virtual void end_step() {}
  // The relaxation factor of the last update (constant/Aitken); 0 for a quasi-Newton update.
  double last_omega() const { return last_omega_; }
  // Secant pairs used by the last quasi-Newton update (after filtering).
  int last_columns() const { return last_columns_; }
  // What carries over from one step to the next, for checkpoints: entries named
  // "<prefix>...". Call between steps.
  virtual void save(StateArchive& state, const std::string& prefix) const;
  virtual void load(const StateArchive& state, const std::string& prefix);

 protected:
  CouplingSettings settings_;
  int k_ = 0;  // the iteration of the step (1 at its first update)
  double last_omega_ = 0;
  int last_columns_ = 0;
};

// One scheme of the registry: its name (coupling.acceleration), a phrase for messages,
// whether it reads the quasi-Newton options (coupling.iqn) and how it is made.
struct AcceleratorScheme {
  std::string name, phrase;
  bool quasi_newton = false;
  int default_reuse_steps = 0;  // coupling.iqn.reuse_steps when not given
  std::function<std::unique_ptr<Accelerator>(const CouplingSettings&)> make;
};
// Every scheme, in the order messages list them (src/acceleration/registry.cpp).
const std::vector<AcceleratorScheme>& accelerator_schemes();
// The scheme of that name (throws std::invalid_argument for an unknown one).
const AcceleratorScheme& accelerator_scheme(const std::string& name);
// A new accelerator of the scheme settings.acceleration.
std::unique_ptr<Accelerator> make_accelerator(const CouplingSettings& settings);

}  // namespace fsi::coupling
