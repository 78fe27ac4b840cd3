#pragma once
#include <memory>
#include <string>
#include <vector>

#include "fsi/common/scene_schema.hpp"
#include "fsi/common/solver_model.hpp"

namespace fsi::models {
// The solid models this server hosts, by the scene's `solid.model` ("sdof", "fem").
// Returns nullptr for an unknown name.
std::unique_ptr<SolidModel> make_solid_model(const std::string& name);
std::vector<std::string> solid_model_names();
// The `solid` section's declaration (every model's keys); the first call declares it to the
// scene schema.
const schema::Key& solid_section();
}  // namespace fsi::models
