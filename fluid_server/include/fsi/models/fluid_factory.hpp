#pragma once
#include <memory>
#include <string>
#include <vector>

#include "fsi/common/scene_schema.hpp"
#include "fsi/common/solver_model.hpp"

namespace fsi::models {
// The fluid models this server hosts, by the scene's `fluid.model` ("surrogate", "fem").
std::unique_ptr<FluidModel> make_fluid_model(const std::string& name);
std::vector<std::string> fluid_model_names();
// The `fluid` section's declaration (every model's keys); the first call declares it to the
// scene schema.
const schema::Key& fluid_section();
}  // namespace fsi::models
