#include "python_tools.hpp"

#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>

#include "fsi/common/log.hpp"
#include "processes.hpp"

namespace fs = std::filesystem;

namespace fsi::launcher {
namespace {

// tools/NAME: an installed fsi (PREFIX/bin) uses its own copy (PREFIX/share/fsi/tools, `cmake --install`),
// a build tree the sources it was built from. The first of them that exists, else the first.
fs::path find_tool(const std::string& name, const fs::path& self_dir) {
  fs::path tool = (self_dir / ".." / "share" / "fsi" / "tools" / name).lexically_normal();
#ifdef FSI_SOURCE_DIR
  if (!fs::exists(tool)) tool = fs::path(FSI_SOURCE_DIR) / "tools" / name;
#endif
  return tool;
}

}  // namespace

std::string python_interpreter() {
  if (const char* env = std::getenv("FSI_PYTHON"); env && *env) return env;
#ifdef FSI_PYTHON
  return FSI_PYTHON;
#else
  return "/usr/bin/python3";
#endif
}

int study_tool(const std::string& subcommand, const std::vector<std::string>& tool_args) {
  fs::path tool = find_tool("fsi_study.py", self_dir());
  if (!fs::exists(tool)) tool = self_dir() / ".." / ".." / "tools" / "fsi_study.py";
  if (!fs::exists(tool)) {
    fsi::logger("fsi")->error("study tool not found: {}", tool.string());
    return 1;
  }
  fsi::logger("fsi")->debug("study tool: {}", tool.string());
  const std::string self = fs::read_symlink("/proc/self/exe").string();
  std::vector<std::string> args{python_interpreter(), tool.string(), subcommand};
  args.insert(args.end(), tool_args.begin(), tool_args.end());
  if (subcommand == "run" || subcommand == "check") args.insert(args.end(), {"--fsi", self});
  auto argv = c_argv(args);
  execvp(argv[0], argv.data());
  fsi::logger("fsi")->error("cannot start {} (set FSI_PYTHON to a python3 with numpy, yaml, zmq and protobuf): {}",
                            argv[0], std::strerror(errno));
  return 1;
}

int plot_folder(const fs::path& folder, const std::string& python, const fs::path& self_dir, bool quiet) {
  const fs::path tool = find_tool("fsi_plot.py", self_dir);
  if (!fs::exists(tool)) {
    logger("fsi")->error("plot tool not found: {}", tool.string());
    return 1;
  }
  std::vector<std::string> args{python, tool.string(), folder.string()};
  if (quiet) args.push_back("--quiet");
  const pid_t pid = fork();
  if (pid < 0) return 1;
  if (pid == 0) {
    auto argv = c_argv(args);
    execvp(argv[0], argv.data());
    std::fprintf(stderr, "cannot start %s (set FSI_PYTHON to a python3 with numpy and matplotlib): %s\n", argv[0],
                 std::strerror(errno));
    _exit(127);
  }
  int status = 0;
  while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

}  // namespace fsi::launcher
