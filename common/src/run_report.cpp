#include "fsi/common/run_report.hpp"

#include <fmt/format.h>

#include <cmath>
#include <fstream>

#include "fsi/common/write_check.hpp"

namespace fsi {
namespace {

nlohmann::json yaml_to_json(const YAML::Node& node) {
  switch (node.Type()) {
    case YAML::NodeType::Map: {
      nlohmann::json j = nlohmann::json::object();
      for (const auto& kv : node) j[kv.first.Scalar()] = yaml_to_json(kv.second);
      return j;
    }
    case YAML::NodeType::Sequence: {
      nlohmann::json j = nlohmann::json::array();
      for (const auto& item : node) j.push_back(yaml_to_json(item));
      return j;
    }
    case YAML::NodeType::Scalar: {
      const std::string& s = node.Scalar();
      if (s == "true" || s == "false") return s == "true";
      try {
        std::size_t used = 0;
        const long long i = std::stoll(s, &used);
        if (used == s.size()) return i;
      } catch (...) {
      }
      try {
        std::size_t used = 0;
        const double d = std::stod(s, &used);
        if (used == s.size()) return d;
      } catch (...) {
      }
      return s;
    }
    default:
      return nullptr;
  }
}

}  // namespace

namespace {
// The files a run writes into --out (and only those: a user's own files stay).
void remove_run_files(const std::filesystem::path& out_dir) {
  for (const auto& e : std::filesystem::directory_iterator(out_dir)) {
    const std::string name = e.path().filename().string();
    const bool ours = name == "summary.json" || name == "summary.json.tmp" || name == "probes.csv" ||
                      name == "iterations.csv" || name == "vtk" || name == "checkpoints" || name == ".ports" ||
                      name == "solid_server.log" || name == "fluid_server.log" || name == "coupler.log" ||
                      name == "commands.json" || name == "timing.csv";
    if (ours) std::filesystem::remove_all(e.path());
  }
}

// summary.json says the run failed before its first step, and there are no checkpoints.
bool failed_before_first_step(const std::filesystem::path& out_dir) {
  namespace fs = std::filesystem;
  if (fs::is_directory(out_dir / "checkpoints") && !fs::is_empty(out_dir / "checkpoints")) return false;
  std::ifstream in(out_dir / "summary.json");
  if (!in) return false;
  const auto summary = nlohmann::json::parse(in, nullptr, false);
  return summary.is_object() && summary.value("status", "") == "failed" && summary.value("steps", -1) == 0 &&
         summary.contains("reason") && summary["reason"].is_string() &&
         summary["reason"].get<std::string>().rfind("while configuring", 0) == 0;
}
}  // namespace

void prepare_output_dir(const std::filesystem::path& out_dir, OutputMode mode) {
  namespace fs = std::filesystem;
  if (fs::exists(out_dir) && !fs::is_directory(out_dir))
    throw std::runtime_error("--out '" + out_dir.string() + "' exists and is not a folder");
  bool empty = !fs::exists(out_dir) || fs::is_empty(out_dir);
  if (!empty && mode == OutputMode::Fresh && failed_before_first_step(out_dir)) {
    // A run that stopped while configuring (a missing file, a mesher's error) computed nothing:
    // its files are replaced without --force, so the corrected run goes into the same --out.
    remove_run_files(out_dir);
    empty = true;  // (a user's own files in it stay, as with --force)
  }
  if (!empty && mode == OutputMode::Fresh) {
    const bool checkpoints = fs::is_directory(out_dir / "checkpoints") && !fs::is_empty(out_dir / "checkpoints");
    throw std::runtime_error("--out '" + out_dir.string() + "' is not empty: " +
                             (checkpoints ? "pass --resume to continue the run in it from its last checkpoint, or "
                                            "--force to replace its results"
                                          : "choose another --out, or pass --force to replace its results (it has "
                                            "no checkpoints to --resume from)"));
  }
  if (!empty && mode == OutputMode::Force) remove_run_files(out_dir);
  fs::create_directories(out_dir);
}

std::size_t csv_rows(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::size_t lines = 0;
  for (std::string line; std::getline(in, line);) ++lines;
  return lines > 0 ? lines - 1 : 0;
}

nlohmann::json scene_to_json(const Scene& scene) { return yaml_to_json(YAML::Load(YAML::Dump(scene.root_node()))); }

RunReport::RunReport(std::filesystem::path out_dir, const Scene& scene, std::string runner)
    : out_dir_(std::move(out_dir)) {
  std::filesystem::create_directories(out_dir_);
  data_["scene_file"] = scene.origin();
  data_["overrides"] = scene.overrides();
  data_["runner"] = runner;
  data_["parameters"] = scene_to_json(scene);
  data_["scene"] = data_["parameters"].value("scene", std::string(""));
  data_["status"] = "running";
  data_["reason"] = "";
}

void RunReport::set_status(const std::string& status, const std::string& reason) {
  data_["status"] = status;
  data_["reason"] = reason;
}

void RunReport::write() const { write_file_atomic(out_dir_ / "summary.json", data_.dump(2) + "\n"); }

ProbeTable ProbeTable::resume(std::filesystem::path path, std::size_t keep_rows) {
  ProbeTable t(path);
  t.csv_ = CsvWriter::resume(path, keep_rows);
  const auto& header = t.csv_.header();
  t.names_.assign(header.begin() + (header.empty() ? 0 : 1), header.end());
  return t;
}

void ProbeTable::add(double time, const std::map<std::string, double>& probes) {
  if (!csv_.is_open()) {
    std::vector<std::string> header{"time"};
    for (const auto& [name, value] : probes) {
      names_.push_back(name);
      header.push_back(name);
    }
    csv_ = CsvWriter(path_, header);
  }
  // time = step * dt: 12 significant digits print it without the round-off of the product
  // (0.06, not 0.060000000000000005) and exactly enough for any dt >= 1e-9 * end; the probes
  // keep 17 (round trip).
  std::vector<std::string> row{fmt::format("{:.12g}", time)};
  for (const auto& name : names_) {
    auto it = probes.find(name);
    row.push_back(fmt::format("{:.17g}", it == probes.end() ? std::nan("") : it->second));
  }
  csv_.row(row);
}

}  // namespace fsi
