#include "bendlab/core/row_file.hpp"

#include <fmt/format.h>

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <limits>

#include "bendlab/core/atomic_file.hpp"
#include "bendlab/core/file_input.hpp"
#include "bendlab/core/types.hpp"

namespace fs = std::filesystem;

namespace bendlab {

namespace {

std::size_t columns_of(const std::string& header) {
  if (header.empty() || header.find('\n') != std::string::npos) throw Error("row file: a header is one non-empty line");
  std::size_t n = 1;
  for (char c : header) n += c == ',';
  return n;
}

// One number as the writer writes it: strtod's whole field, overflow refused, underflow kept
// (a subnormal is a number the writer wrote).
bool parse_number(const std::string& field, double& value) {
  if (field.empty() || field == "nan") {  // undefined (files of older versions wrote "nan")
    value = std::numeric_limits<double>::quiet_NaN();
    return true;
  }
  char* end = nullptr;
  errno = 0;
  value = std::strtod(field.c_str(), &end);
  if (end != field.c_str() + field.size()) return false;
  return !(errno == ERANGE && std::isinf(value) && field.find("inf") == std::string::npos);
}

// The rows of `text` after its header: at most `limit` (all with limit < 0); complete lines only.
std::vector<NumberRow> parse_rows(const std::string& text, const fs::path& path, const std::string& header,
                                  std::int64_t limit, std::size_t* bytes) {
  const std::size_t columns = columns_of(header);
  const std::size_t first_end = text.find('\n');
  if (first_end == std::string::npos || text.compare(0, first_end, header) != 0)
    throw Error(fmt::format("'{}' line 1: expected the header \"{}\"", path.string(), header));
  std::vector<NumberRow> rows;
  std::size_t pos = first_end + 1;
  std::int64_t line = 1;
  while ((limit < 0 || static_cast<std::int64_t>(rows.size()) < limit) && pos < text.size()) {
    const std::size_t end = text.find('\n', pos);
    if (end == std::string::npos) break;  // a half-written last line
    ++line;
    NumberRow row;
    std::size_t start = pos;
    while (true) {
      const std::size_t comma = text.find(',', start);
      const std::size_t stop = comma == std::string::npos || comma > end ? end : comma;
      double v = 0;
      if (!parse_number(text.substr(start, stop - start), v))
        throw Error(fmt::format("'{}' line {}: \"{}\" is not a number", path.string(), line,
                                text.substr(start, stop - start)));
      row.push_back(v);
      if (stop == end) break;
      start = stop + 1;
    }
    if (row.size() != columns)
      throw Error(fmt::format("'{}' line {}: {} columns, the header has {}", path.string(), line, row.size(), columns));
    rows.push_back(std::move(row));
    pos = end + 1;
  }
  if (limit >= 0 && static_cast<std::int64_t>(rows.size()) < limit)
    throw Error(fmt::format("'{}' holds {} complete rows, expected {}", path.string(), rows.size(), limit));
  if (bytes) *bytes = pos;
  return rows;
}

}  // namespace

RowFile::RowFile(fs::path path, std::size_t columns, std::int64_t rows)
    : path_(std::move(path)), columns_(columns), rows_(rows) {
  out_.open(path_, std::ios::app | std::ios::binary);
  if (!out_) throw Error(fmt::format("cannot open '{}' for writing", path_.string()));
}

RowFile RowFile::create(const fs::path& path, const std::string& header) {
  const std::size_t columns = columns_of(header);
  AtomicFile f(path);
  f.stream() << header << '\n';
  f.commit();
  return RowFile(path, columns, 0);
}

RowFile RowFile::resume(const fs::path& path, const std::string& header, std::int64_t rows) {
  const std::string text = read_regular_file(path, "the time series");
  std::size_t bytes = 0;
  parse_rows(text, path, header, rows, &bytes);
  AtomicFile f(path);
  f.stream().write(text.data(), static_cast<std::streamsize>(bytes));
  f.commit();
  return RowFile(path, columns_of(header), rows);
}

void RowFile::append(const NumberRow& values) {
  if (values.size() != columns_)
    throw Error(fmt::format("'{}': a row of {} values, the header has {} columns", path_.string(), values.size(),
                            columns_));
  for (std::size_t k = 0; k < values.size(); ++k)
    if (std::isinf(values[k]))
      throw Error(fmt::format("'{}': column {} of row {} is {}, not a number a result file can hold", path_.string(),
                              k + 1, rows_ + 1, values[k]));
  std::string line;
  for (std::size_t k = 0; k < values.size(); ++k) {
    if (k) line += ',';
    if (!std::isnan(values[k])) line += fmt::format("{:.12g}", values[k]);  // undefined: an empty field
  }
  line += '\n';
  out_ << line;
  out_.flush();
  if (!out_) throw Error(fmt::format("cannot write to '{}'", path_.string()));
  ++rows_;
}

std::vector<NumberRow> RowFile::read_head(const fs::path& path, const std::string& header, std::int64_t rows,
                                          std::size_t* bytes) {
  if (rows < 0) throw Error("row file: a negative row count");
  return parse_rows(read_regular_file(path, "the time series"), path, header, rows, bytes);
}

std::vector<NumberRow> RowFile::read_all(const fs::path& path, const std::string& header) {
  return parse_rows(read_regular_file(path, "the time series"), path, header, -1, nullptr);
}

}  // namespace bendlab
