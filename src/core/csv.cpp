#include "bendlab/core/csv.hpp"

#include <fmt/format.h>

#include <cmath>

#include "bendlab/core/atomic_file.hpp"

namespace bendlab {

void CsvTable::add(const std::string& name, const Scalars& values) {
  names_.push_back(name);
  columns_.push_back(values);
}

void CsvTable::add(const std::vector<std::string>& names, const Points& values) {
  if (names.size() != 3) throw Error("CsvTable: a vector field needs three column names");
  for (int c = 0; c < 3; ++c) add(names[c], values.col(c));
}

void CsvTable::write(const std::filesystem::path& path) const {
  const Eigen::Index rows = columns_.empty() ? 0 : columns_.front().size();
  for (size_t c = 0; c < columns_.size(); ++c)
    if (columns_[c].size() != rows)
      throw Error(fmt::format("CsvTable: column '{}' has {} rows, expected {}", names_[c], columns_[c].size(), rows));
  AtomicFile file(path);
  auto& out = file.stream();
  for (size_t c = 0; c < names_.size(); ++c) out << (c ? "," : "") << names_[c];
  out << '\n';
  std::string line;
  for (Eigen::Index r = 0; r < rows; ++r) {
    line.clear();
    for (size_t c = 0; c < columns_.size(); ++c) {
      if (c) line += ',';
      const double v = columns_[c][r];
      line += std::isnan(v) ? std::string("nan") : fmt::format("{:.17g}", v);
    }
    out << line << '\n';
  }
  file.commit();
}

}  // namespace bendlab
