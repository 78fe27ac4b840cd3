#include "fsi/common/table_writer.hpp"

#include <fmt/format.h>

#include <cerrno>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <system_error>

#include "fsi/common/write_check.hpp"

namespace fsi {

CsvWriter::CsvWriter(const std::filesystem::path& path, const std::vector<std::string>& columns)
    : out_(path), columns_(columns.size()), path_(path), header_(columns) {
  if (!out_) throw WriteError(path, errno ? errno : EIO);
  row(columns);
}

CsvWriter CsvWriter::resume(const std::filesystem::path& path, std::size_t keep_rows,
                            const std::vector<std::string>& columns) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error(fmt::format("cannot resume '{}': it does not exist", path.string()));
  std::string header_line;
  if (!std::getline(in, header_line))
    throw std::runtime_error(fmt::format("cannot resume '{}': it has no header", path.string()));
  std::vector<std::string> header;
  {
    std::stringstream ss(header_line);
    for (std::string c; std::getline(ss, c, ',');) header.push_back(c);
  }
  if (!columns.empty() && header != columns)
    throw std::runtime_error(fmt::format("cannot resume '{}': its columns differ from this run's", path.string()));
  std::size_t rows = 0;
  std::streamoff keep_bytes = static_cast<std::streamoff>(header_line.size() + 1);
  for (std::string line; rows < keep_rows && std::getline(in, line); ++rows)
    keep_bytes += static_cast<std::streamoff>(line.size() + 1);
  if (rows < keep_rows)
    throw std::runtime_error(fmt::format("cannot resume '{}': it has {} data rows, the checkpoint needs {}",
                                         path.string(), rows, keep_rows));
  in.close();
  std::filesystem::resize_file(path, static_cast<std::uintmax_t>(keep_bytes));
  CsvWriter w;
  w.out_.open(path, std::ios::app);
  if (!w.out_) throw WriteError(path, errno ? errno : EIO);
  w.columns_ = header.size();
  w.written_ = static_cast<std::uintmax_t>(keep_bytes);
  w.path_ = path;
  w.header_ = header;
  return w;
}

void CsvWriter::row(const std::vector<std::string>& values) {
  if (values.size() != columns_)
    throw std::invalid_argument(
        fmt::format("{}: row has {} values, header has {}", path_.string(), values.size(), columns_));
  std::string line;
  for (std::size_t i = 0; i < values.size(); ++i) (line += (i ? "," : "")) += values[i];
  line += '\n';
  errno = 0;
  out_ << line;
  try {
    check_written(out_, path_);
  } catch (const WriteError&) {
    // Keep the rows written before whole: cut a row that reached the disk in part.
    out_.close();
    std::error_code ignored;
    std::filesystem::resize_file(path_, written_, ignored);
    throw;
  }
  written_ += line.size();
}

void CsvWriter::row(const std::vector<double>& values) {
  std::vector<std::string> text;
  text.reserve(values.size());
  for (double v : values) text.push_back(fmt::format("{:.17g}", v));
  row(text);
}

}  // namespace fsi
