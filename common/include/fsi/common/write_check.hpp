#pragma once
// Writes that are checked: a full disk, a quota or an I/O error while writing any output
// file (tables, VTK, summary.json, checkpoints) is an error naming the file, never a
// silently short file.
//
// Test hook: FSI_TEST_WRITE_FAILURE=NAME[:N] makes the N-th (default: the first) and every
// later checked write of this process to a file whose name is NAME fail as a full disk (ENOSPC).
#include <filesystem>
#include <ostream>
#include <stdexcept>
#include <string>

namespace fsi {

// "cannot write 'FILE': no space left on device" (or the system's text for other errors).
class WriteError : public std::runtime_error {
 public:
  WriteError(const std::filesystem::path& file, int error);
  const std::filesystem::path& file() const { return file_; }
  int error() const { return error_; }

 private:
  std::filesystem::path file_;
  int error_;
};

// Whether an error message (also one relayed from another process) is a failed write.
bool is_write_failure(const std::string& message);
// The text of a write error: "no space left on device" for ENOSPC.
std::string write_error_text(int error);
// True when FSI_TEST_WRITE_FAILURE asks this write to `file` to fail (counts the calls).
bool injected_write_failure(const std::filesystem::path& file);
// Flushes `out` and throws WriteError if anything written to it did not reach `file`.
void check_written(std::ostream& out, const std::filesystem::path& file);
// Writes `text` to `file` through `file`.tmp and a rename; on failure removes the .tmp; on a
// full disk then tries to write `file` in place (the old one's space); else throws WriteError.
void write_file_atomic(const std::filesystem::path& file, const std::string& text);

}  // namespace fsi
