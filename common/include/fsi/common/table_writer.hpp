#pragma once
// CSV tables written row by row and flushed after each row, so a run that dies keeps
// every row written before; a row that cannot be written (a full disk) is an error.
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

namespace fsi {

class CsvWriter {
 public:
  CsvWriter() = default;
  CsvWriter(const std::filesystem::path& path, const std::vector<std::string>& columns);
  // Continues an existing table (a resumed run): keeps its header and its first
  // `keep_rows` data rows, drops the rest, appends from there. Throws naming the file when
  // it has fewer rows than that or its header differs from `columns` (when not empty).
  static CsvWriter resume(const std::filesystem::path& path, std::size_t keep_rows,
                          const std::vector<std::string>& columns = {});
  CsvWriter(CsvWriter&&) = default;
  CsvWriter& operator=(CsvWriter&&) = default;
  bool is_open() const { return out_.is_open(); }
  const std::vector<std::string>& header() const { return header_; }
  std::size_t columns() const { return columns_; }
  // Writes one row; throws std::invalid_argument if its size differs from the header's, and
  // WriteError (the file named, the partial row cut off) if it does not reach the disk.
  void row(const std::vector<double>& values);
  void row(const std::vector<std::string>& values);

 private:
  std::ofstream out_;
  std::size_t columns_ = 0;
  std::uintmax_t written_ = 0;  // bytes of the complete rows on disk
  std::filesystem::path path_;
  std::vector<std::string> header_;
};

}  // namespace fsi
