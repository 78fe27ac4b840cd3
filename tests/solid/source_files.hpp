#pragma once
// The source tree and its files, for the solid tests (they run from the build tree; the source
// tree is found from this header's path).
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace fsi::solid::test {

inline std::filesystem::path repo_root() {
  return std::filesystem::path(__FILE__).parent_path().parent_path().parent_path();
}

inline std::string read_text(const std::filesystem::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

}  // namespace fsi::solid::test
