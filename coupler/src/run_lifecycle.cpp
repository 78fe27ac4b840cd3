// A run's lifecycle: the state its first step starts from (the scene's initial state, a
// --resume checkpoint, a fork), its tables (new or continued), and its checkpoints.
#include <algorithm>
#include <cmath>
#include <fstream>
#include <future>
#include <limits>
#include <tuple>

#include "fsi/common/interface_geometry.hpp"
#include "fsi/common/write_check.hpp"
#include "fsi/coupling/coupler.hpp"
#include "fsi/coupling/predictor.hpp"
#include "run_parts.hpp"

namespace fsi::coupling {
using namespace run_detail;

void Coupler::start_state(Run& r) {
  if (r.checkpoints || resume_)
    for (const auto& [side, ok, who] : {std::tuple{"solid", solid_.supports_checkpoint(), solid_.name()},
                                        std::tuple{"fluid", fluid_.supports_checkpoint(), fluid_.name()}})
      if (!ok)
        throw Stop{"failed", fmt::format("{} needs checkpoints, which the {} '{}' does not support",
                                         resume_ ? "--resume" : "time.checkpoint_every", side, who)};
  find_restart(r);
  if (r.restart)
    load_restart(r);
  else
    initial_state(r);
  if (r.checkpoints)
    r.data["checkpoints"] = {{"every", r.time.checkpoint_every},
                             {"keep", r.time.checkpoint_keep},
                             {"written", 0},
                             {"seconds", 0.0},
                             {"folder", (out_dir_ / "checkpoints").string()}};
  if (r.restart) r.data["resumed_from_step"] = r.restart->step;
  r.data["wall_time_earlier_segments"] = r.wall_before;
}

void Coupler::find_restart(Run& r) {
  if (resume_) {
    std::vector<std::string> skipped;
    r.restart = r.store.newest(&skipped);
    for (const auto& why : skipped) r.log->warn("skipping checkpoint {}", why);
    if (!r.restart && !allow_fresh_start_)
      throw Stop{"failed", fmt::format("--resume: no complete checkpoint in {}{}", (out_dir_ / "checkpoints").string(),
                                       skipped.empty() ? std::string() : " (" + skipped.front() + ")")};
    if (!r.restart) r.log->warn("no complete checkpoint yet: starting again from step 0");
  }
  // A forked run (fsi run --from): OUT/forked_from.json names the checkpoint it started from;
  // at that checkpoint the scene may differ (the changes are listed in summary.json), and
  // its probes.csv and iterations.csv hold only the steps after it.
  if (std::filesystem::exists(out_dir_ / "forked_from.json")) {
    try {
      std::ifstream in(out_dir_ / "forked_from.json");
      r.fork = nlohmann::json::parse(in);
    } catch (const std::exception& e) {
      throw Stop{"failed", fmt::format("{}: does not parse ({})", (out_dir_ / "forked_from.json").string(), e.what())};
    }
    r.data["forked_from"] = r.fork;
  }
  r.fork_step = r.fork.is_object() ? r.fork.value("step", 0) : 0;
  r.fork_iterations = r.fork.is_object() ? r.fork.value("iterations", 0L) : 0L;
  r.at_fork = r.fork.is_object() && r.restart && r.restart->step == r.fork_step;
}

void Coupler::load_restart(Run& r) {
  const CheckpointStore::Loaded& restart = *r.restart;
  const int step = restart.step;
  auto diffs = parameter_differences(restart.manifest.value("parameters", nlohmann::json::object()), r.parameters);
  // A resumed run may be extended: time.end is the one key that may differ.
  if (!r.at_fork) {
    const auto end =
        std::find_if(diffs.begin(), diffs.end(), [](const std::string& d) { return d.rfind("time.end:", 0) == 0; });
    if (end != diffs.end()) {
      r.log->info("extended: {}", *end);
      r.data["extended"] = *end;
      diffs.erase(end);
    }
  }
  if (r.at_fork) {
    // The steps are numbered from t = 0 (t_n = n dt): another dt would put the fork at another
    // time and run to time.end in the wrong number of steps.
    for (const auto& d : diffs)
      if (d.rfind("time.dt:", 0) == 0)
        throw Stop{"failed", fmt::format("--from {}: a fork keeps the time step ({}); start a run with another "
                                         "time.dt from rest, or from another run's fluid state (--initial-state)",
                                         restart.dir.string(), d)};
    r.data["forked_from"]["changed"] = diffs;
    for (const auto& d : diffs) r.log->info("forked with {}", d);
  } else if (!diffs.empty()) {
    std::string list;
    for (const auto& d : diffs) list += "\n  " + d;
    throw Stop{"failed", fmt::format("--resume: the scene differs from the one checkpoint {} was written with "
                                     "({} key(s)):{}",
                                     restart.dir.string(), diffs.size(), list)};
  }
  for (const char* part : {"solid", "fluid", "coupler"})
    if (!restart.parts.count(part))
      throw Stop{"failed", fmt::format("checkpoint {} has no '{}' part", restart.dir.string(), part)};
  r.log->info("resuming from the checkpoint of step {} (t = {}) in {}", step, restart.time, restart.dir.string());
  {
    Timer t(times_.solid);
    solid_.load_checkpoint(step, restart.time, restart.parts.at("solid"));
  }
  {
    Timer t(times_.fluid);
    fluid_.load_checkpoint(step, restart.time, restart.parts.at("fluid"));
  }
  const StateArchive c =
      StateArchive::parse(restart.parts.at("coupler"), "coupler checkpoint of step " + std::to_string(step));
  if (c.integer("step") != step)
    throw Stop{"failed",
               fmt::format("checkpoint {}: coupler part is of step {}", restart.dir.string(), c.integer("step"))};
  read_coupler_state(r, c);
  if (r.at_fork) convert_forked_predictor(r, c);
  r.wall_before = restart.manifest.value("wall_seconds", 0.0);
  r.out.steps = step;
  r.out.resumed_from = step;
}

void Coupler::State::save(StateArchive& c) const {
  c.put("force_n", force_n);
  c.put("force_nm1", force_nm1);
  c.put("force_nm2", force_nm2);
  c.put("force_nm3", force_nm3);
  c.put("forces_known", static_cast<std::int64_t>(forces_known));
  c.put("d_s_prev", d_s_prev);
  c.put("d_f_prev", d_f_prev);
  c.put("work_solid", work_solid);
  c.put("work_fluid", work_fluid);
  c.put("work_fluid_on_solid", work_fluid_on_solid);
  c.put("work_uncancelled", work_uncancelled);
  c.put("v_s_prev", v_s_prev);
  if (mapped_mass.rows() > 0) {
    std::vector<double> rows, cols, values;
    for (int col = 0; col < mapped_mass.outerSize(); ++col)
      for (NodalMatrix::InnerIterator it(mapped_mass, col); it; ++it)
        rows.push_back(double(it.row())), cols.push_back(double(it.col())), values.push_back(it.value());
    c.put("mapped_mass.rows", rows);
    c.put("mapped_mass.cols", cols);
    c.put("mapped_mass.values", values);
  }
}

// The coupler's own entries of a checkpoint (the accelerator's and the scheme's are theirs).
bool Coupler::State::load(const StateArchive& c, Eigen::Index nv, Eigen::Index nf, Eigen::Index ns,
                          const std::string& dir, bool fork, bool* resampled) {
  // A fork into another fluid.substeps: whole windows of the checkpoint's sample count.
  const Eigen::Index stored = c.vector("force_n").size();
  const bool other_samples = fork && stored != nf && nv > 0 && stored > 0 && stored % nv == 0;
  const Eigen::Index n = other_samples ? stored : nf;
  force_n = c.vector("force_n", n);
  force_nm1 = c.vector("force_nm1", n);
  // Before the predictors' longer history: F_n and F_{n-1}.
  force_nm2 = c.has("force_nm2") ? c.vector("force_nm2", n) : force_nm1;
  force_nm3 = c.has("force_nm3") ? c.vector("force_nm3", n) : force_nm2;
  if (other_samples) resample_forces(nv, nf);
  if (resampled) *resampled = other_samples;
  forces_known = c.has("forces_known") ? static_cast<int>(c.integer("forces_known")) : 2;
  d_s_prev = c.vector("d_s_prev", nv);
  d_f_prev = c.vector("d_f_prev", d_f_prev.size());
  if (c.has("v_s_prev")) v_s_prev = c.vector("v_s_prev", nv);
  if (c.has("work_uncancelled")) work_uncancelled = c.real("work_uncancelled");
  if (c.has("mapped_mass.values")) {
    const Eigen::VectorXd rows = c.vector("mapped_mass.rows"), cols = c.vector("mapped_mass.cols"),
                          values = c.vector("mapped_mass.values");
    if (rows.size() != values.size() || cols.size() != values.size())
      throw Stop{"failed", fmt::format("checkpoint {}: coupler part has a malformed mapped_mass", dir)};
    std::vector<Eigen::Triplet<double>> t;
    for (Eigen::Index k = 0; k < values.size(); ++k) {
      const auto row = static_cast<Eigen::Index>(rows[k]), col = static_cast<Eigen::Index>(cols[k]);
      if (row < 0 || row >= ns || col < 0 || col >= ns)
        throw Stop{"failed", fmt::format("checkpoint {}: coupler mapped_mass entry ({}, {}) outside {} nodes", dir, row,
                                         col, ns)};
      t.emplace_back(row, col, values[k]);
    }
    mapped_mass.resize(ns, ns);
    mapped_mass.setFromTriplets(t.begin(), t.end());
  }
  work_solid = c.real("work_solid");
  work_fluid = c.real("work_fluid");
  work_fluid_on_solid = c.real("work_fluid_on_solid");
  return c.has("mapped_mass.values");
}

void Coupler::State::resample_forces(Eigen::Index nv, Eigen::Index nf) {
  const Eigen::Index samples = nf / nv;
  auto end_value = [nv](const Eigen::VectorXd& f) { return Eigen::VectorXd(f.tail(nv)); };
  const Eigen::VectorXd e0 = end_value(force_n), e1 = end_value(force_nm1), e2 = end_value(force_nm2),
                        e3 = end_value(force_nm3);
  // The window from `a` (the previous window's end) to `b` (this window's end), sample j of
  // `samples` at the fraction j / samples.
  auto window = [&](const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
    Eigen::VectorXd f(nf);
    for (Eigen::Index j = 1; j <= samples; ++j)
      f.segment((j - 1) * nv, nv) = a + (static_cast<double>(j) / static_cast<double>(samples)) * (b - a);
    return f;
  };
  force_n = window(e1, e0);
  force_nm1 = window(e2, e1);
  force_nm2 = window(e3, e2);
  force_nm3 = window(e3, e3);
}

void Coupler::read_coupler_state(Run& r, const StateArchive& c) {
  State& st = r.state;
  const Eigen::Index ns = static_cast<Eigen::Index>(solid_interface_.nodes());
  const std::string dir = r.restart->dir.string();
  bool resampled = false;
  if (!st.load(c, r.nv, r.nv * r.n_fluid, ns, dir, r.at_fork, &resampled) && r.implicit && r.gamma_n1 > 0)
    r.log->warn(
        "checkpoint {} holds no interface mass (an earlier version): the first solve of step {} uses the "
        "solid's own int N^T N",
        dir, r.restart->step + 1);
  r.out.iterations = static_cast<long>(c.integer("iterations"));
  if (r.at_fork && !r.scheme->has_history(c)) {
    // Forked from another scheme: the scheme's history starts from the checkpoint's state (the
    // fluid's loads of its last step), as a run from rest starts from the initial state's.
    FluidLoads loads;
    {
      Timer t(times_.fluid);
      loads = fluid_.initial_loads(map_.to_fluid(st.d_s_prev), map_.to_fluid(st.v_s_prev));
    }
    r.scheme->initial_loads(r, loads);
    r.data["forked_from"]["scheme_history"] = "started from the checkpoint's state";
    r.log->info("forked into coupling.scheme {}: its history starts from the checkpoint's step {}", r.scheme->name(),
                r.restart->step);
  } else {
    r.scheme->load(c);
  }
  if (resampled) {
    // The secant pairs live in the old waveform's space: the accelerator starts afresh.
    r.accelerator = make_accelerator(settings_);
    r.data["forked_from"]["forces_resampled"] =
        fmt::format("{} -> {} samples per window", c.vector("force_n").size() / r.nv, r.n_fluid);
    r.log->info("forked into fluid.substeps {}: the force histories resampled in time ({} -> {} samples per window)",
                r.n_fluid, c.vector("force_n").size() / r.nv, r.n_fluid);
  } else {
    r.accelerator->load(c, "accelerator.");
  }
}

void Coupler::convert_forked_predictor(Run& r, const StateArchive& c) {
  // F_n holds the algorithm's own Robin part: Algorithm 2's force is the load the solid
  // felt plus gamma_N1 C v_n. Forked into another algorithm or gamma_N1, convert it (the
  // predictor of the next step), and drop the accelerator's reused secant pairs (they
  // live in the old force's space).
  const auto& old =
      r.restart->manifest.value("parameters", nlohmann::json::object()).value("coupling", nlohmann::json::object());
  auto number = [](const nlohmann::json& j, const char* key, double fallback) {
    if (!j.contains(key)) return fallback;
    const auto& v = j.at(key);
    return v.is_number() ? v.get<double>() : v.is_string() ? std::stod(v.get<std::string>()) : fallback;
  };
  const double gamma = r.gamma_n1;
  const int old_algorithm = static_cast<int>(number(old, "algorithm", static_cast<double>(settings_.algorithm)));
  const double old_gamma = number(old, "gamma_n1", gamma);
  if (old_algorithm == static_cast<int>(settings_.algorithm) && old_gamma == gamma) return;
  State& st = r.state;
  const NodalMatrix c_mass = st.mapped_mass.rows() > 0 ? st.mapped_mass : nodal_interface_mass(solid_interface_, {});
  if (!c.has("v_s_prev"))
    r.log->warn(
        "checkpoint {} holds no interface velocity (an earlier version): the first step's predictor "
        "keeps the old algorithm's force",
        r.restart->dir.string());
  else {
    for (Eigen::VectorXd* f : {&st.force_n, &st.force_nm1, &st.force_nm2, &st.force_nm3})
      for (int j = 0; j < r.n_fluid; ++j) {  // every sample of the waveform
        auto block = f->segment(j * r.nv, r.nv);
        if (old_algorithm == 2 && old_gamma > 0) block -= old_gamma * apply_nodal(c_mass, st.v_s_prev);
        if (r.implicit && gamma > 0) block += gamma * apply_nodal(c_mass, st.v_s_prev);
      }
    r.data["forked_from"]["predictor_converted"] = true;
  }
  r.accelerator = make_accelerator(settings_);
  r.log->info(
      "forked from algorithm {} (gamma_N1 {}) into algorithm {} (gamma_N1 {}): the force predictor "
      "converted, the reused secant pairs dropped",
      old_algorithm, old_gamma, static_cast<int>(settings_.algorithm), gamma);
}

void Coupler::initial_state(Run& r) {
  State& st = r.state;
  const Eigen::VectorXd &d_s = st.d_s_prev, &v_s = st.v_s_prev;  // the scene's initial state
  FluidLoads loads;
  {
    Timer t(times_.fluid);
    loads = fluid_.initial_loads(map_.to_fluid(d_s), map_.to_fluid(v_s));
  }
  Timer t(times_.coupler);
  r.scheme->initial_loads(r, loads);
  st.mapped_mass = map_mass(r, loads);
  st.force_n = -robin_force(map_.to_solid(loads.traction_force), map_.to_solid(loads.velocity_integral), v_s, d_s,
                            st.mapped_mass);
  if (r.time.output_every > 0) {  // the initial state, t = 0
    write_output(r, StepInfo{0.0, r.time.dt, 0, 0},
                 InterfaceFields{d_s, v_s, st.force_n, map_.to_solid(loads.traction_force),
                                 map_.to_solid(loads.velocity_integral), map_.to_fluid(d_s), map_.to_fluid(v_s),
                                 loads.traction_force, loads.velocity_integral});
  }
  st.force_n = repeated(st.force_n, r.n_fluid);  // a waveform: constant over the fluid's substeps
  st.force_nm1 = st.force_nm2 = st.force_nm3 = st.force_n;
}

void Coupler::open_tables(Run& r) {
  std::vector<std::string> iteration_columns{"step",
                                             "time",
                                             "iteration",
                                             "residual",
                                             "force_norm",
                                             "solid_newton",
                                             "fluid_iterations",
                                             "traction_change",
                                             "traction_norm",
                                             "displacement_change",
                                             "displacement_norm",
                                             "velocity_change",
                                             "velocity_norm"};
  for (const auto& m : settings_.measures) iteration_columns.push_back(m.name());
  for (const auto& name : r.scheme->columns()) iteration_columns.push_back(name);
  const bool resume_tables = r.restart && !r.at_fork;
  const auto kept_steps = resume_tables ? static_cast<std::size_t>(r.restart->step - r.fork_step) : 0;
  r.probes.emplace(resume_tables ? ProbeTable::resume(out_dir_ / "probes.csv", kept_steps)
                                 : ProbeTable(out_dir_ / "probes.csv"));
  r.iterations = resume_tables ? CsvWriter::resume(out_dir_ / "iterations.csv",
                                                   static_cast<std::size_t>(r.out.iterations - r.fork_iterations),
                                                   iteration_columns)
                               : CsvWriter(out_dir_ / "iterations.csv", iteration_columns);
  // Wall time per step (not byte-identical across runs, so apart from probes.csv): cumulative
  // seconds of the run, its fluid and solid requests, for cost per simulated second.
  const std::vector<std::string> timing_columns{"step", "time", "wall", "fluid", "solid", "iterations"};
  const auto timing_path = out_dir_ / "timing.csv";
  r.timing = resume_tables && std::filesystem::exists(timing_path)
                 ? CsvWriter::resume(timing_path, kept_steps, timing_columns)
                 : CsvWriter(timing_path, timing_columns);
  r.progress.emplace("coupler", r.time.steps, r.out.steps);
  r.segment_start = now();
}

void Coupler::save_checkpoint(Run& r, int n, double t_np1) {
  Timer t(times_.checkpoint);
  const State& st = r.state;
  std::map<std::string, std::string> parts;
  parts["solid"] = solid_.save_checkpoint(n, t_np1);
  parts["fluid"] = fluid_.save_checkpoint(n, t_np1);
  StateArchive c;
  c.put("step", static_cast<std::int64_t>(n));
  st.save(c);
  c.put("iterations", static_cast<std::int64_t>(r.out.iterations));
  r.scheme->save(c);
  r.accelerator->save(c, "accelerator.");
  parts["coupler"] = c.serialize();
  nlohmann::json manifest = {{"scene", r.data.value("scene", std::string())},
                             {"scene_file", scene_.origin()},
                             {"overrides", scene_.overrides()},
                             {"parameters", r.parameters},
                             {"iterations", r.out.iterations},
                             {"wall_seconds", r.wall_before + (now() - r.segment_start)}};
  const auto written = r.store.write(n, t_np1, manifest, parts);
  auto& info = r.data["checkpoints"];
  info["written"] = info.value("written", 0) + 1;
  info["last_step"] = n;
  info["last_bytes"] = written.bytes;
  info["parts_bytes"] = {
      {"solid", parts["solid"].size()}, {"fluid", parts["fluid"].size()}, {"coupler", parts["coupler"].size()}};
}

}  // namespace fsi::coupling
