// fluid_run: runs a fluid-only scene with NavierStokesFluid (the same steps as
// `fluid_server --standalone`), writing probes.csv and summary.json.
//
// Sample runs (from the repository root):
//   build-fluid/bin/fluid_run configs/dfg_2d1.yaml --out out/dfg_2d1
//   build-fluid/bin/fluid_run configs/dfg_2d1.yaml --out out/dfg_2d1_h01 --set fluid.mesh.size=0.01
//   build-fluid/bin/fluid_run configs/dfg_2d2.yaml --out out/dfg_2d2
#include <fmt/format.h>

#include <chrono>
#include <cstring>
#include <fstream>
#include <iostream>

#include "fsi/common/config.hpp"
#include "fsi/common/log.hpp"
#include "fsi/common/table_writer.hpp"
#include "fsi/fluid/navier_stokes_fluid.hpp"

int main(int argc, char** argv) {
  // 1. Parse the command line.
  std::string scene_path, out_dir;
  std::vector<std::string> overrides;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--out") && i + 1 < argc) out_dir = argv[++i];
    else if (!std::strcmp(argv[i], "--set") && i + 1 < argc) overrides.push_back(argv[++i]);
    else if (argv[i][0] != '-' && scene_path.empty()) scene_path = argv[i];
    else {
      std::cerr << "usage: fluid_run SCENE.yaml --out DIR [--set key=value]...\n";
      return 2;
    }
  }
  if (scene_path.empty() || out_dir.empty()) {
    std::cerr << "usage: fluid_run SCENE.yaml --out DIR [--set key=value]...\n";
    return 2;
  }
  auto log = fsi::logger("fluid_run");
  try {
    // 2. Load the scene; read the keys the server's driver reads.
    auto scene = fsi::Scene::load(scene_path, overrides);
    const auto root = scene.root();
    const auto name = root.get<std::string>("scene", "scene");
    (void)root.get<std::string>("description", "");
    const auto time = scene.section("time");
    const double dt = time.get<double>("dt"), end = time.get<double>("end");
    const int output_every = time.get<int>("output_every", 0);  // VTK: the same policy as fsi run
    const auto fluid = scene.section("fluid");
    if (fluid.get<std::string>("model") != "fem") fluid.fail("model", "fluid_run runs only the fem model");

    // 3. Configure.
    fsi::FluidSetup setup;
    setup.dt = dt;
    setup.end_time = end;
    setup.output_dir = out_dir;
    std::filesystem::create_directories(out_dir);
    const auto t0 = std::chrono::steady_clock::now();
    fsi::fluid::NavierStokesFluid model;
    model.configure(fluid, setup);
    scene.check_all_used("fluid");
    const double setup_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

    // 4. Time loop: zero interface motion, accept every step.
    const auto iface = model.interface();
    const Eigen::VectorXd zero = Eigen::VectorXd::Zero(2 * static_cast<Eigen::Index>(iface.nodes()));
    fsi::CsvWriter csv;
    std::map<std::string, double> probes;
    const int steps = static_cast<int>(std::llround(end / dt));
    int iterations = 0;
    if (output_every > 0) model.write_output(fsi::StepInfo{0.0, dt, 0, 0});  // the initial state
    for (int n = 1; n <= steps; ++n) {
      fsi::StepInfo info{n * dt, dt, n, 0};
      iterations += model.solve_step(info, zero, zero).nonlinear_iterations;
      probes = model.accept_step(info);
      if (output_every > 0 && n % output_every == 0) model.write_output(info);
      if (!csv.is_open()) {
        std::vector<std::string> cols{"time"};
        for (const auto& [k, _] : probes) cols.push_back(k);
        csv = fsi::CsvWriter(std::filesystem::path(out_dir) / "probes.csv", cols);
      }
      std::vector<double> row{info.time};
      for (const auto& [_, v] : probes) row.push_back(v);
      csv.row(row);
    }
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

    // 5. Summary.
    std::ofstream summary(std::filesystem::path(out_dir) / "summary.json");
    summary << fmt::format("{{\n  \"scene\": \"{}\",\n  \"dofs\": {},\n  \"nodes\": {},\n  \"triangles\": {},\n"
                           "  \"steps\": {},\n  \"linear_solves\": {},\n  \"setup_seconds\": {:.3f},\n  \"wall_seconds\": {:.3f}",
                           name, model.solver().dofs(), model.solver().mesh().node_count(),
                           model.solver().mesh().triangle_count(), steps, iterations, setup_seconds, wall);
    summary << ",\n  \"fluid_breakdown\": {";
    bool first = true;
    for (const auto& [k, v] : model.timings()) {
      summary << fmt::format("{}\"{}\": {:.4f}", first ? "" : ", ", k, v);
      first = false;
    }
    summary << "}";
    for (const auto& [k, v] : probes) summary << fmt::format(",\n  \"final_{}\": {:.10g}", k, v);
    summary << "\n}\n";
    log->info("{}: {} steps, {} solves, {} unknowns, wall {:.1f}s", name, steps, iterations, model.solver().dofs(), wall);
    return 0;
  } catch (const std::exception& e) {
    log->error("{}", e.what());
    return 1;
  }
}
