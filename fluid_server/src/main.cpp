// fluid_server: hosts a fluid model behind the wire protocol (proto/), or runs a scene's
// fluid alone.
//
// Sample runs:
//   fluid_server --bind tcp://0.0.0.0:5556                 # serve a coupler on another host
//   fluid_server --bind 'tcp://127.0.0.1:*' --port-file p  # free port, written to p
//   fluid_server --standalone configs/dfg_2d1.yaml --out runs/dfg_2d1
#include <CLI/CLI.hpp>

#include "fsi/common/log.hpp"
#include "fsi/common/process.hpp"
#include "fsi/common/standalone.hpp"
#include "fsi/models/fluid_factory.hpp"
#include "fsi/protocol/service.hpp"

int main(int argc, char** argv) {
  fsi::init_process();
  // 1. Parse options.
  CLI::App app{"FSI fluid server"};
  std::string bind = "tcp://127.0.0.1:5556", port_file, scene_path, out_dir = "out/fluid";
  std::vector<std::string> overrides;
  double idle_timeout = 0;
  app.add_option("--bind", bind, "endpoint to bind (tcp://HOST:PORT, port * = any free port)");
  app.add_option("--port-file", port_file, "write the bound endpoint to this file");
  app.add_option("--idle-timeout", idle_timeout, "exit after this many seconds without a request (0 = never)");
  app.add_option("--standalone", scene_path, "run the scene's fluid alone (no coupler)");
  app.add_option("--out", out_dir, "output folder for --standalone");
  app.add_option("--set", overrides, "override a scene key: dotted.key=value (with --standalone)");
  CLI11_PARSE(app, argc, argv);

  // 2. Run: standalone, or serve.
  try {
    if (!scene_path.empty()) {
      const auto scene = fsi::Scene::load(scene_path, overrides);
      return fsi::run_standalone_fluid(fsi::models::make_fluid_model, scene, out_dir);
    }
    fsi::protocol::FluidService service(fsi::models::make_fluid_model, "fsi fluid_server 0.1");
    return fsi::protocol::run_server(service, bind, port_file, idle_timeout, "fluid_server");
  } catch (const std::exception& e) {
    fsi::logger("fluid_server")->error("{}", e.what());
    return 1;
  }
}
