#pragma once
// The project's Python tools the launcher hands over to: fsi plot (tools/fsi_plot.py), fsi study and
// fsi list (tools/fsi_study.py).
#include <filesystem>
#include <string>
#include <vector>

namespace fsi::launcher {

// The Python interpreter of the project's Python tools: $FSI_PYTHON, else the one CMake found
// with numpy, yaml, zmq and protobuf (cmake/FsiPython.cmake).
std::string python_interpreter();

// `fsi study` / `fsi list`: hands over to the study tool (tools/fsi_study.py SUBCOMMAND) with every
// option passed on unchanged; a sweep also gets this executable as --fsi so every run uses the
// same build. Replaces this process; returns only on failure.
int study_tool(const std::string& subcommand, const std::vector<std::string>& tool_args);

// Runs tools/fsi_plot.py on a run or study folder with `python`; returns its exit code.
int plot_folder(const std::filesystem::path& folder, const std::string& python, const std::filesystem::path& self_dir,
                bool quiet = false);

}  // namespace fsi::launcher
