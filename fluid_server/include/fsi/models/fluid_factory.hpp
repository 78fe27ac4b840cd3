#pragma once
#include <memory>
#include <string>
#include <vector>

#include "fsi/common/solver_model.hpp"

namespace fsi::models {
// The fluid models this server hosts, by the scene's `fluid.model` ("surrogate", "fem").
std::unique_ptr<FluidModel> make_fluid_model(const std::string& name);
std::vector<std::string> fluid_model_names();
}  // namespace fsi::models
