// The accelerator registry: every scheme of coupling.acceleration, one line each. A new scheme
// is its own file (a class derived from Accelerator, or from QuasiNewton) and one line here.
#include <stdexcept>

#include "fsi/coupling/acceleration.hpp"
#include "schemes.hpp"

namespace fsi::coupling {

const std::vector<AcceleratorScheme>& accelerator_schemes() {
  static const std::vector<AcceleratorScheme> schemes{
      {"constant", "the paper: beta", false, 0, make_constant_relaxation},
      {"aitken", "dynamic relaxation", false, 0, make_aitken},
      {"iqn-ils", "interface quasi-Newton", true, 8, make_iqn_ils},
      {"iqn-imvj", "interface quasi-Newton, multi-vector Jacobian", true, 0, make_iqn_imvj},
  };
  return schemes;
}

const AcceleratorScheme& accelerator_scheme(const std::string& name) {
  for (const auto& s : accelerator_schemes())
    if (s.name == name) return s;
  throw std::invalid_argument("unknown coupling.acceleration '" + name + "'");
}

std::unique_ptr<Accelerator> make_accelerator(const CouplingSettings& settings) {
  return accelerator_scheme(settings.acceleration).make(settings);
}

void Accelerator::begin_step() { k_ = 0; }

void Accelerator::save(StateArchive& state, const std::string& prefix) const {
  state.put(prefix + "last_omega", last_omega_);
}

void Accelerator::load(const StateArchive& state, const std::string& prefix) {
  begin_step();
  last_omega_ = state.real(prefix + "last_omega");
}

}  // namespace fsi::coupling
