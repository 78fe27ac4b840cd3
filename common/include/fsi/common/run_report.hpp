#pragma once
// What every run leaves in its output folder:
//   summary.json  scene, every parameter, status (completed / diverged / failed) and its
//                 reason, steps, iterations, wall time split; rewritten at every accepted
//                 step and at the end, so it is valid if the run dies;
//   probes.csv    `time` then one column per probe, one row per accepted step (flushed).
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <string>

#include "fsi/common/config.hpp"
#include "fsi/common/table_writer.hpp"

namespace fsi {

// How a runner treats an --out folder that is not empty.
enum class OutputMode { Fresh, Force, Resume };
// Fresh: refuses a folder that exists and is not empty (naming --resume and --force);
// Force: removes the files a run writes (summary, tables, logs, vtk/, checkpoints/) first;
// Resume: keeps everything. Creates the folder. Throws std::runtime_error.
void prepare_output_dir(const std::filesystem::path& out_dir, OutputMode mode);
// Rows of a CSV table after its header (0 if there is no file).
std::size_t csv_rows(const std::filesystem::path& path);

// The scene (after --set overrides) as JSON: numbers stay numbers.
nlohmann::json scene_to_json(const Scene& scene);

class RunReport {
 public:
  RunReport(std::filesystem::path out_dir, const Scene& scene, std::string runner);
  nlohmann::json& data() { return data_; }
  void set_status(const std::string& status, const std::string& reason = "");
  void write() const;  // atomic (write temp, rename); throws WriteError naming the file
  const std::filesystem::path& out_dir() const { return out_dir_; }

 private:
  std::filesystem::path out_dir_;
  nlohmann::json data_;
};

class ProbeTable {
 public:
  explicit ProbeTable(std::filesystem::path path) : path_(std::move(path)) {}
  // Continues the table of a resumed run after its first `keep_rows` rows.
  static ProbeTable resume(std::filesystem::path path, std::size_t keep_rows);
  // Columns are fixed by the first call: `time` then the sorted probe names.
  void add(double time, const std::map<std::string, double>& probes);

 private:
  std::filesystem::path path_;
  CsvWriter csv_;
  std::vector<std::string> names_;
};

}  // namespace fsi
