#pragma once
// The command line shared by solid_server and fluid_server: serve a coupler on an endpoint,
// or run the scene's solver alone (--standalone SCENE --out DIR [--set k=v ...]).
#include <functional>
#include <memory>
#include <string>

#include "fsi/common/config.hpp"
#include "fsi/protocol/service.hpp"

namespace fsi::protocol {

struct ServerProgram {
  std::string kind;  // "solid" or "fluid": names the program, logger and defaults
  std::function<int(const Scene& scene, const std::string& out_dir)> standalone;
  std::function<std::unique_ptr<Service>()> service;
};

// Parses the options, runs, catches and reports; returns the exit code.
int server_main(int argc, char** argv, const ServerProgram& program);

}  // namespace fsi::protocol
