#include "fsi/protocol/server_main.hpp"

#include <CLI/CLI.hpp>

#include "fsi/common/log.hpp"
#include "fsi/common/process.hpp"
#include "fsi/common/version.hpp"
#include "fsi/protocol/client.hpp"
#include "fsi/transport/transport.hpp"

namespace fsi::protocol {

int server_main(int argc, char** argv, const ServerProgram& program) {
  fsi::init_process();
  const std::string name = program.kind + "_server";
  // 1. Parse options.
  CLI::App app{"FSI " + program.kind + " server"};
  std::string bind = "tcp://127.0.0.1:5555", port_file, scene_path, out_dir = "out/" + program.kind;
  std::vector<std::string> overrides;
  double idle_timeout = 0;
  std::string curve_keys;
  app.set_version_flag("--version",
                       fsi::version_line(name) + "\nprotocol fsi.v1, version " + std::to_string(kProtocolVersion));
  app.add_option("--bind", bind, "endpoint to bind (tcp://HOST:PORT, port * = any free port)");
  app.add_option("--port-file", port_file, "write the bound endpoint to this file");
  app.add_option("--idle-timeout", idle_timeout, "exit after this many seconds without a request (0 = never)");
  app.add_option("--curve-keys", curve_keys,
                 "encrypt and authenticate with ZeroMQ CURVE: the folder made by `fsi keys DIR` "
                 "(server.key_secret; "
                 "accepts the clients whose *.key certificates are in it)");
  app.add_option("--standalone", scene_path, "run the scene's " + program.kind + " alone (no coupler)");
  app.add_option("--out", out_dir, "output folder for --standalone");
  app.add_option("--set", overrides, "override a scene key: dotted.key=value (with --standalone)");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : 1;  // command-line errors exit 1
  }

  // 2. Run: standalone, or serve.
  try {
    if (!scene_path.empty()) return program.standalone(Scene::load(scene_path, overrides), out_dir);
    const auto service = program.service();
    const auto keys = curve_keys.empty() ? transport::CurveKeys{} : transport::load_curve_keys(curve_keys, "server");
    return run_server(*service, bind, port_file, idle_timeout, name, keys);
  } catch (const std::exception& e) {
    fsi::logger(name)->error("{}", e.what());
    return 1;
  }
}

}  // namespace fsi::protocol
