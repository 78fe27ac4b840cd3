#include "fsi/coupling/checkpoint.hpp"

#include <fcntl.h>
#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <regex>
#include <stdexcept>
#include <system_error>

#include "fsi/common/state.hpp"
#include "fsi/common/write_check.hpp"

namespace fs = std::filesystem;

namespace fsi::coupling {
namespace {

// Throws WriteError naming `path` (a full disk: "no space left on device").
void write_synced(const fs::path& path, const std::string& bytes) {
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) throw WriteError(path, errno);
  std::size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (n < 0) {
      if (errno == EINTR) continue;
      const int err = errno;
      ::close(fd);
      throw WriteError(path, err);
    }
    done += static_cast<std::size_t>(n);
  }
  if (injected_write_failure(path)) {
    ::close(fd);
    throw WriteError(path, ENOSPC);
  }
  if (::fsync(fd) != 0) {
    const int err = errno;
    ::close(fd);
    throw WriteError(path, err);
  }
  if (::close(fd) != 0) throw WriteError(path, errno);
}

void sync_dir(const fs::path& dir) {
  const int fd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd >= 0) {
    ::fsync(fd);
    ::close(fd);
  }
}

std::string read_file(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error("cannot read " + path.string());
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

std::vector<std::pair<int, fs::path>> complete_folders(const fs::path& dir) {
  std::vector<std::pair<int, fs::path>> out;
  if (!fs::is_directory(dir)) return out;
  static const std::regex name("step_([0-9]{8})");
  for (const auto& e : fs::directory_iterator(dir)) {
    std::smatch m;
    const std::string n = e.path().filename().string();
    if (e.is_directory() && std::regex_match(n, m, name)) out.emplace_back(std::stoi(m[1]), e.path());
  }
  std::sort(out.begin(), out.end(), [](const auto& a, const auto& b) { return a.first > b.first; });
  return out;
}

void flatten(const nlohmann::json& j, const std::string& prefix, std::map<std::string, nlohmann::json>& out) {
  if (j.is_object()) {
    for (auto it = j.begin(); it != j.end(); ++it)
      flatten(it.value(), prefix.empty() ? it.key() : prefix + "." + it.key(), out);
  } else {
    out[prefix] = j;
  }
}

// Equal as the solvers see them: 1 and 1.0 are the same number.
bool same_value(const nlohmann::json& a, const nlohmann::json& b) {
  if (a.is_number() && b.is_number()) return a.get<double>() == b.get<double>();
  if (a.is_array() && b.is_array()) {
    if (a.size() != b.size()) return false;
    for (std::size_t i = 0; i < a.size(); ++i)
      if (!same_value(a[i], b[i])) return false;
    return true;
  }
  if (a.is_object() && b.is_object()) {
    if (a.size() != b.size()) return false;
    for (auto it = a.begin(); it != a.end(); ++it)
      if (!b.contains(it.key()) || !same_value(it.value(), b.at(it.key()))) return false;
    return true;
  }
  return a == b;
}

}  // namespace

CheckpointStore::CheckpointStore(fs::path dir, int keep) : dir_(std::move(dir)), keep_(std::max(1, keep)) {}

std::string CheckpointStore::folder_name(int step) { return fmt::format("step_{:08d}", step); }

CheckpointStore::Written CheckpointStore::write(int step, double time, nlohmann::json manifest,
                                                const std::map<std::string, std::string>& parts) {
  fs::create_directories(dir_);
  const fs::path final_dir = dir_ / folder_name(step);
  const fs::path tmp = dir_ / (folder_name(step) + ".tmp");
  fs::remove_all(tmp);
  fs::create_directories(tmp);
  Written written{final_dir, 0};
  manifest["format_version"] = kFormatVersion;
  manifest["step"] = step;
  manifest["time"] = time;
  try {
    for (const auto& [name, bytes] : parts) {
      const std::string file = name + ".state";
      write_synced(tmp / file, bytes);
      manifest["parts"][name] = {{"file", file}, {"bytes", bytes.size()}, {"crc32", crc32_hex(bytes)}};
      written.bytes += bytes.size();
    }
    const std::string text = manifest.dump(2) + "\n";
    write_synced(tmp / "manifest.json", text);
    written.bytes += text.size();
  } catch (...) {
    std::error_code ignored;
    fs::remove_all(tmp, ignored);  // an incomplete checkpoint is not left behind (nor its space taken)
    throw;
  }
  sync_dir(tmp);
  fs::remove_all(final_dir);
  fs::rename(tmp, final_dir);
  sync_dir(dir_);
  // Keep the newest `keep` complete ones.
  const auto all = complete_folders(dir_);
  for (std::size_t i = static_cast<std::size_t>(keep_); i < all.size(); ++i) fs::remove_all(all[i].second);
  return written;
}

CheckpointStore::Loaded CheckpointStore::read(const fs::path& dir) {
  const fs::path manifest_path = dir / "manifest.json";
  if (!fs::exists(manifest_path)) throw std::runtime_error("no manifest.json (incomplete)");
  Loaded c;
  c.manifest = nlohmann::json::parse(read_file(manifest_path));
  const int version = c.manifest.at("format_version").get<int>();
  if (version != kFormatVersion)
    throw std::runtime_error(fmt::format("format version {}, this build reads {}", version, kFormatVersion));
  c.step = c.manifest.at("step").get<int>();
  c.time = c.manifest.at("time").get<double>();
  for (const auto& [name, part] : c.manifest.at("parts").items()) {
    const std::string bytes = read_file(dir / part.at("file").get<std::string>());
    if (bytes.size() != part.at("bytes").get<std::size_t>())
      throw std::runtime_error(fmt::format("part '{}' has {} bytes, the manifest says {}", name, bytes.size(),
                                           part.at("bytes").get<std::size_t>()));
    if (crc32_hex(bytes) != part.at("crc32").get<std::string>())
      throw std::runtime_error(fmt::format("part '{}' fails its checksum", name));
    c.parts[name] = bytes;
  }
  c.dir = dir;
  return c;
}

std::optional<CheckpointStore::Loaded> CheckpointStore::newest(std::vector<std::string>* skipped) const {
  for (const auto& [step, dir] : complete_folders(dir_)) {
    try {
      Loaded c = read(dir);
      if (c.step != step) throw std::runtime_error(fmt::format("manifest says step {}", c.step));
      return c;
    } catch (const std::exception& e) {
      if (skipped) skipped->push_back(fmt::format("{}: {}", dir.string(), e.what()));
    }
  }
  return std::nullopt;
}

std::vector<std::string> parameter_differences(const nlohmann::json& saved, const nlohmann::json& now) {
  std::map<std::string, nlohmann::json> a, b;
  flatten(saved, "", a);
  flatten(now, "", b);
  std::vector<std::string> out;
  for (const auto& [key, value] : a) {
    const auto it = b.find(key);
    if (it == b.end())
      out.push_back(fmt::format("{}: {} (checkpoint) vs absent (now)", key, value.dump()));
    else if (!same_value(it->second, value))
      out.push_back(fmt::format("{}: {} (checkpoint) vs {} (now)", key, value.dump(), it->second.dump()));
  }
  for (const auto& [key, value] : b)
    if (!a.count(key)) out.push_back(fmt::format("{}: absent (checkpoint) vs {} (now)", key, value.dump()));
  return out;
}

}  // namespace fsi::coupling
