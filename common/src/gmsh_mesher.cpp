// Run-time meshing of gmsh .geo files with a cache (gmsh_mesher.hpp).
#include "fsi/common/gmsh_mesher.hpp"

#include <fmt/format.h>
#include <unistd.h>

#include <cstdlib>
#include <fstream>
#include <functional>
#include <sstream>
#include <stdexcept>

#include "fsi/common/log.hpp"

namespace fsi {
namespace {

std::string read_text(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

}  // namespace

std::filesystem::path default_mesh_cache() {
  if (const char* env = std::getenv("FSI_MESH_CACHE"); env && *env) return env;
  if (const char* xdg = std::getenv("XDG_CACHE_HOME"); xdg && *xdg)
    return std::filesystem::path(xdg) / "fsi" / "meshes";
  if (const char* home = std::getenv("HOME"); home && *home)
    return std::filesystem::path(home) / ".cache" / "fsi" / "meshes";
  return std::filesystem::temp_directory_path() / "fsi_fluid_meshes";
}

std::filesystem::path mesh_geo(const std::filesystem::path& geo, const std::map<std::string, double>& parameters,
                               const std::filesystem::path& cache_dir, int order, int dimension,
                               const std::string& who) {
  std::string key = read_text(geo);
  if (order != 1) key += fmt::format("\norder={}", order);
  if (dimension != 2) key += fmt::format("\ndimension={}", dimension);
  for (const auto& [name, value] : parameters) key += fmt::format("\n{}={:.17g}", name, value);
  const auto hash = std::hash<std::string>{}(key);
  std::filesystem::create_directories(cache_dir);
  const auto out = cache_dir / fmt::format("{}_{:016x}.msh", geo.stem().string(), hash);
  if (std::filesystem::exists(out)) return out;
  const auto tmp = cache_dir / fmt::format("{}_{:016x}.{}.tmp.msh", geo.stem().string(), hash, ::getpid());
  const auto log_file = cache_dir / fmt::format("{}_{:016x}.log", geo.stem().string(), hash);
  std::string cmd = fmt::format("gmsh -{} -format msh22 -v 2", dimension);
  if (order != 1) cmd += fmt::format(" -order {}", order);
  for (const auto& [name, value] : parameters) cmd += fmt::format(" -setnumber {} {:.17g}", name, value);
  cmd += fmt::format(" '{}' -o '{}' > '{}' 2>&1", geo.string(), tmp.string(), log_file.string());
  std::string what;
  for (const auto& [name, value] : parameters)
    what += fmt::format("{}{} = {:g}", what.empty() ? "" : ", ", name, value);
  fsi::logger(who)->info("meshing {} with gmsh ({}{}; log {})", geo.filename().string(), what,
                         order != 1 ? fmt::format(", order {}", order) : "", log_file.string());
  fsi::logger(who)->debug("{}", cmd);
  const int rc = std::system(cmd.c_str());
  if (rc != 0 || !std::filesystem::exists(tmp))
    throw std::runtime_error(
        fmt::format("gmsh failed on '{}' (exit {}): {}\n{}", geo.string(), rc, cmd, read_text(log_file)));
  std::filesystem::rename(tmp, out);
  return out;
}

}  // namespace fsi
