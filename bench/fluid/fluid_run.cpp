// fluid_run: deprecated alias of `fsi run` (the one runner of every scene). Prints one
// deprecation line and runs `fsi run ARGS...` from the same folder, so old commands keep
// working with fsi run's output: probes.csv columns `fluid.cd`, `fluid.cl`, `fluid.dp`, ...,
// summary.json, fluid_server.log, vtk/ every time.output_every steps.
//
//   fluid_run configs/dfg_2d1.yaml --out runs/dfg_2d1   ==   fsi run configs/dfg_2d1.yaml --out runs/dfg_2d1
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include "fsi/common/version.hpp"

int main(int argc, char** argv) {
  if (argc == 2 && !std::strcmp(argv[1], "--version")) {
    std::printf("%s\n", fsi::version_line("fluid_run").c_str());
    return 0;
  }
  const auto fsi_path = std::filesystem::read_symlink("/proc/self/exe").parent_path() / "fsi";
  std::fprintf(stderr, "fluid_run is deprecated and will be removed: use `fsi run SCENE --out DIR [--set k=v]`\n");
  std::vector<std::string> args{fsi_path.string(), "run"};
  for (int i = 1; i < argc; ++i) args.emplace_back(argv[i]);
  std::vector<char*> c_args;
  for (auto& a : args) c_args.push_back(a.data());
  c_args.push_back(nullptr);
  execv(c_args[0], c_args.data());
  std::fprintf(stderr, "fluid_run: cannot start %s: %s\n", c_args[0], std::strerror(errno));
  return 1;
}
