#pragma once
// A CSV file of numeric rows that a run appends to, one row per record, and a resume cuts back to
// the rows of its checkpoint: a header line, then rows of numbers written with 12 significant
// digits ("{:.12g}"), an undefined value (NaN: no cells, no cell-free layer) as an empty field,
// and no infinity (append refuses it): no result file holds a non-finite number. The reader takes
// whatever the writer writes, subnormal numbers included, and an empty field or "nan" (files of
// older versions) as NaN.
//
// Appends are flushed and checked (a failed write throws bendlab::Error naming the file); the
// cut of a resume rewrites the file through a temporary and an atomic rename, so it is never
// half-written. (The capsule's timeseries.csv has its own format: capsule/time_series.hpp.)
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

namespace bendlab {

using NumberRow = std::vector<double>;

class RowFile {
 public:
  /// A new file holding only `header` (replacing any file at path, atomically).
  static RowFile create(const std::filesystem::path& path, const std::string& header);
  /// Keeps the header and the first `rows` rows of an existing file byte for byte (atomic
  /// rewrite), then appends after them. Throws, before any change, as read_head does.
  static RowFile resume(const std::filesystem::path& path, const std::string& header, std::int64_t rows);

  /// Appends a row of the header's column count and flushes; throws bendlab::Error for another
  /// count, an infinite value or a failed write (NaN is written as an empty field).
  void append(const NumberRow& values);
  std::int64_t rows() const { return rows_; }
  const std::filesystem::path& path() const { return path_; }

  /// The first `rows` rows (the rows after them are not read: a killed run may have left half a
  /// row there). Throws bendlab::Error naming the file and line for anything but a regular file,
  /// another header, a row that is not `columns` numbers, or fewer complete rows. `bytes`, if
  /// given, receives the length of the header and those rows in the file.
  static std::vector<NumberRow> read_head(const std::filesystem::path& path, const std::string& header,
                                          std::int64_t rows, std::size_t* bytes = nullptr);
  /// Every complete row.
  static std::vector<NumberRow> read_all(const std::filesystem::path& path, const std::string& header);

 private:
  RowFile(std::filesystem::path path, std::size_t columns, std::int64_t rows);
  std::filesystem::path path_;
  std::size_t columns_ = 0;
  std::ofstream out_;
  std::int64_t rows_ = 0;
};

}  // namespace bendlab
