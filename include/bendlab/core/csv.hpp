#pragma once
// Column tables written as CSV through AtomicFile: a header line, then one row per entry with
// full double precision; NaN is written as `nan`.
#include <filesystem>
#include <string>
#include <vector>

#include "bendlab/core/types.hpp"

namespace bendlab {

class CsvTable {
 public:
  /// Adds a column of per-vertex scalars.
  void add(const std::string& name, const Scalars& values);
  /// Adds the three columns prefix+x, prefix+y, prefix+z (or the given names) of an N x 3 array.
  void add(const std::vector<std::string>& names, const Points& values);
  /// Writes the table; throws bendlab::Error if the columns differ in length or the write fails.
  void write(const std::filesystem::path& path) const;

 private:
  std::vector<std::string> names_;
  std::vector<Scalars> columns_;
};

}  // namespace bendlab
