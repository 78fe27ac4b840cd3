#pragma once
// The accelerator schemes' factories, one per file of this folder; the registry
// (registry.cpp) lists them under their names.
#include <memory>

#include "fsi/coupling/acceleration.hpp"

namespace fsi::coupling {

std::unique_ptr<Accelerator> make_constant_relaxation(const CouplingSettings& settings);  // constant.cpp
std::unique_ptr<Accelerator> make_aitken(const CouplingSettings& settings);               // aitken.cpp
std::unique_ptr<Accelerator> make_iqn_ils(const CouplingSettings& settings);              // iqn_ils.cpp
std::unique_ptr<Accelerator> make_iqn_imvj(const CouplingSettings& settings);             // iqn_imvj.cpp

}  // namespace fsi::coupling
