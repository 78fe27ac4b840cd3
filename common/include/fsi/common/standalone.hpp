#pragma once
// Runs one solver alone from a scene (no coupler, no other process): the CSM benchmarks
// (solid alone) and the DFG/CFD benchmarks (fluid alone). Writes summary.json and
// probes.csv into `out_dir` step by step, logs progress with an ETA.
#include <filesystem>
#include <functional>
#include <memory>

#include "fsi/common/config.hpp"
#include "fsi/common/scene_schema.hpp"
#include "fsi/common/solver_model.hpp"

namespace fsi {

using SolidFactory = std::function<std::unique_ptr<SolidModel>(const std::string& model)>;
using FluidFactory = std::function<std::unique_ptr<FluidModel>(const std::string& model)>;

// Builds the model named by `section.model` ("solid" / "fluid" in messages); an unknown name
// is a ConfigError naming the key and its line.
template <class Model>
std::unique_ptr<Model> make_model(const std::function<std::unique_ptr<Model>(const std::string&)>& factory,
                                  const ConfigSection& section, const char* kind) {
  schema::require_valid(section);  // every key of the section, before the model builds anything
  const auto name = section.get<std::string>("model");
  auto model = factory(name);
  if (!model) section.fail("model", std::string("names no ") + kind + " model this server knows ('" + name + "')");
  return model;
}

// Both build the model named by `<section>.model`, configure it (unknown keys anywhere in
// the scene are an error), run every step with a zero interface load, and return the
// process exit code (0 completed, 2 diverged, 1 failed, 130 interrupted by SIGINT/SIGTERM)
// after writing the summary.
int run_standalone_solid(const SolidFactory& factory, const Scene& scene, const std::filesystem::path& out_dir);
int run_standalone_fluid(const FluidFactory& factory, const Scene& scene, const std::filesystem::path& out_dir);

// Time section shared by all runners: `time: {dt: ..., end: ..., output_every: N}`.
struct TimeSettings {
  double dt = 0;
  double end = 0;
  int steps = 0;                             // round(end / dt)
  int output_every = 0;                      // write VTK every N steps (0 = never)
  VtkFormat vtk_format = VtkFormat::Binary;  // binary (zlib, appended) or ascii
  int checkpoint_every = 0;                  // coupled runs: a checkpoint every N accepted steps (0 = off)
  int checkpoint_keep = 2;                   // the newest K complete checkpoints are kept
};
TimeSettings read_time(const Scene& scene);
// The declaration of the `time` section (read by read_time).
const schema::Key& time_section();
// time.vtk_format of a scene (default binary), for a server that reads only its own section.
VtkFormat read_vtk_format(const Scene& scene);

// Progress line every few seconds: step, time, extra text, ETA.
class Progress {
 public:
  // `first_step`: the step a resumed run starts after (the ETA counts only steps done here).
  Progress(std::string logger_name, int total_steps, int first_step = 0);
  // After step `step` (t = time): a line every 2 s and at the last step. The ETA is the mean
  // wall time of the steps after the first one done here (the first carries start-up costs)
  // times the steps left; after one step, that step's time.
  void update(int step, double time, const std::string& extra = "");
  // Inside a step (e.g. after each coupling iteration): a line once the step has run for 2 s
  // and 2 s passed since the last line, so a long step is not silent.
  void within(int step, const std::string& extra);

 private:
  std::string logger_name_;
  int total_;
  int first_;
  double interval_;  // seconds between lines: 2 ($FSI_PROGRESS_INTERVAL)
  double start_;
  double last_ = -1e9;
  double step_start_ = 0;   // wall time at the end of the previous step (or at the start)
  double first_done_ = -1;  // wall time at the end of the first step done here
  int first_done_step_ = 0;
};

}  // namespace fsi
