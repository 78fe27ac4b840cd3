#pragma once
// What every run leaves in its output folder:
//   summary.json  scene, every parameter, status (completed / diverged / failed) and its
//                 reason, steps, iterations, wall time split; rewritten at every accepted
//                 step and at the end, so it is valid if the run dies;
//   probes.csv    `time` then one column per probe, one row per accepted step (flushed).
#include <nlohmann/json.hpp>

#include <filesystem>
#include <map>
#include <string>

#include "fsi/common/config.hpp"
#include "fsi/common/table_writer.hpp"

namespace fsi {

// The scene (after --set overrides) as JSON: numbers stay numbers.
nlohmann::json scene_to_json(const Scene& scene);

class RunReport {
 public:
  RunReport(std::filesystem::path out_dir, const Scene& scene, std::string runner);
  nlohmann::json& data() { return data_; }
  void set_status(const std::string& status, const std::string& reason = "");
  void write() const;  // atomic (write temp, rename)
  const std::filesystem::path& out_dir() const { return out_dir_; }

 private:
  std::filesystem::path out_dir_;
  nlohmann::json data_;
};

class ProbeTable {
 public:
  explicit ProbeTable(std::filesystem::path path) : path_(std::move(path)) {}
  // Columns are fixed by the first call: `time` then the sorted probe names.
  void add(double time, const std::map<std::string, double>& probes);

 private:
  std::filesystem::path path_;
  CsvWriter csv_;
  std::vector<std::string> names_;
};

}  // namespace fsi
