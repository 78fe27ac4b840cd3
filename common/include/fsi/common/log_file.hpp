#pragma once
// Copies every log line, of the loggers that exist and of those made later, to a file as
// well as to stderr (a standalone run's OUT/<server>.log).
#include <filesystem>

namespace fsi {
// Truncates `file` (created with its folder). Call once per process; a second call replaces
// the first file.
void add_log_file(const std::filesystem::path& file);
}  // namespace fsi
