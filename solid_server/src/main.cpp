// solid_server: hosts a solid model behind the wire protocol (proto/), or runs a scene's
// solid alone.
//
// Sample runs:
//   solid_server --bind tcp://0.0.0.0:5555                 # serve a coupler on another host
//   solid_server --bind 'tcp://127.0.0.1:*' --port-file p  # free port, written to p
//   solid_server --standalone configs/csm1.yaml --out runs/csm1
#include <CLI/CLI.hpp>

#include "fsi/common/log.hpp"
#include "fsi/common/process.hpp"
#include "fsi/common/standalone.hpp"
#include "fsi/models/solid_factory.hpp"
#include "fsi/protocol/service.hpp"

int main(int argc, char** argv) {
  fsi::init_process();
  // 1. Parse options.
  CLI::App app{"FSI solid server"};
  std::string bind = "tcp://127.0.0.1:5555", port_file, scene_path, out_dir = "out/solid";
  std::vector<std::string> overrides;
  double idle_timeout = 0;
  app.add_option("--bind", bind, "endpoint to bind (tcp://HOST:PORT, port * = any free port)");
  app.add_option("--port-file", port_file, "write the bound endpoint to this file");
  app.add_option("--idle-timeout", idle_timeout, "exit after this many seconds without a request (0 = never)");
  app.add_option("--standalone", scene_path, "run the scene's solid alone (no coupler)");
  app.add_option("--out", out_dir, "output folder for --standalone");
  app.add_option("--set", overrides, "override a scene key: dotted.key=value (with --standalone)");
  CLI11_PARSE(app, argc, argv);

  // 2. Run: standalone, or serve.
  try {
    if (!scene_path.empty()) {
      const auto scene = fsi::Scene::load(scene_path, overrides);
      return fsi::run_standalone_solid(fsi::models::make_solid_model, scene, out_dir);
    }
    fsi::protocol::SolidService service(fsi::models::make_solid_model, "fsi solid_server 0.1");
    return fsi::protocol::run_server(service, bind, port_file, idle_timeout, "solid_server");
  } catch (const std::exception& e) {
    fsi::logger("solid_server")->error("{}", e.what());
    return 1;
  }
}
