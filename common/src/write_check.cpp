#include "fsi/common/write_check.hpp"

#include <fmt/format.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <mutex>
#include <system_error>

namespace fsi {

WriteError::WriteError(const std::filesystem::path& file, int error)
    : std::runtime_error(fmt::format("cannot write '{}': {}", file.string(), write_error_text(error))),
      file_(file),
      error_(error) {}

std::string write_error_text(int error) {
  if (error == ENOSPC) return "no space left on device";
  if (error == EDQUOT) return "disk quota exceeded";
  return error ? std::strerror(error) : "write failed";
}

bool is_write_failure(const std::string& message) { return message.find("cannot write '") != std::string::npos; }

bool injected_write_failure(const std::filesystem::path& file) {
  static std::mutex mutex;
  static long count = 0;
  const char* env = std::getenv("FSI_TEST_WRITE_FAILURE");
  if (!env || !*env) return false;
  std::string name = env;
  long at = 1;
  if (const auto colon = name.rfind(':'); colon != std::string::npos) {
    at = std::atol(name.c_str() + colon + 1);
    name.resize(colon);
  }
  if (file.filename().string() != name) return false;
  std::lock_guard lock(mutex);
  return ++count >= at;
}

void check_written(std::ostream& out, const std::filesystem::path& file) {
  out.flush();
  const int err = errno;
  if (!out) throw WriteError(file, err ? err : EIO);
  if (injected_write_failure(file)) throw WriteError(file, ENOSPC);
}

namespace {
void write_whole(const std::filesystem::path& path, const std::filesystem::path& named, const std::string& text) {
  errno = 0;
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) throw WriteError(named, errno ? errno : EIO);
  out << text;
  check_written(out, named);
  out.close();
  if (!out) throw WriteError(named, errno ? errno : EIO);
}
}  // namespace

void write_file_atomic(const std::filesystem::path& file, const std::string& text) {
  const std::filesystem::path tmp = file.string() + ".tmp";
  try {
    write_whole(tmp, file, text);
    std::filesystem::rename(tmp, file);
  } catch (const WriteError& e) {
    std::error_code ignored;
    std::filesystem::remove(tmp, ignored);
    // A full disk: the new text may still fit in the place of the old (a summary rewritten
    // with its final status), in place of the atomic rename.
    if (e.error() != ENOSPC || !std::filesystem::exists(file)) throw;
    write_whole(file, file, text);
  } catch (...) {
    std::error_code ignored;
    std::filesystem::remove(tmp, ignored);
    throw;
  }
}

}  // namespace fsi
