#pragma once
// Checkpoints of a coupled run on disk: OUT/checkpoints/step_00000050/ holds one file per
// part ("solid.state", "fluid.state", "coupler.state": opaque bytes) and manifest.json
// (format version, scene, overrides, the effective parameters, step, time, and each part's
// size and CRC-32). A checkpoint is written into a temporary folder, every file fsync'ed,
// the manifest last, then renamed into place: it is complete only when its manifest is
// there and every part matches its size and checksum. Older checkpoints beyond `keep` are
// removed after a new one is complete.
//
//   CheckpointStore store(out_dir / "checkpoints", 2);
//   store.write(50, 1.0, manifest_extra, {{"solid", bytes_s}, {"fluid", bytes_f}, {"coupler", bytes_c}});
//   if (auto c = store.newest()) { ... c->parts.at("solid") ... }
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

namespace fsi::coupling {

class CheckpointStore {
 public:
  static constexpr int kFormatVersion = 1;
  CheckpointStore(std::filesystem::path dir, int keep);

  struct Written {
    std::filesystem::path dir;
    std::size_t bytes = 0;
  };
  // `manifest` holds the caller's fields (scene, parameters, ...); step, time, format and
  // the parts' sizes and checksums are added here.
  Written write(int step, double time, nlohmann::json manifest, const std::map<std::string, std::string>& parts);

  struct Loaded {
    int step = 0;
    double time = 0;
    std::filesystem::path dir;
    nlohmann::json manifest;
    std::map<std::string, std::string> parts;
  };
  // The newest complete checkpoint; incomplete or corrupt ones are skipped, each with its
  // reason in `skipped` (if given). nullopt when there is none.
  std::optional<Loaded> newest(std::vector<std::string>* skipped = nullptr) const;
  // One checkpoint folder, checked as newest() checks each (throws std::runtime_error naming
  // what is wrong). The launcher reads checkpoints with these two as well.
  static Loaded read(const std::filesystem::path& dir);

  // "step_00000050"
  static std::string folder_name(int step);

 private:
  std::filesystem::path dir_;
  int keep_;
};

// Keys whose values differ between two scenes' parameters (as in summary.json), as
// "key: A (checkpoint) vs B (now)" lines; empty when they agree.
std::vector<std::string> parameter_differences(const nlohmann::json& saved, const nlohmann::json& now);

}  // namespace fsi::coupling
