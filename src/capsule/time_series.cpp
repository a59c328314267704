#include "bendlab/capsule/time_series.hpp"

#include <fmt/format.h>

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <sstream>

#include "bendlab/core/atomic_file.hpp"
#include "bendlab/core/file_input.hpp"

namespace bendlab {

const char* time_series_header() { return "gamma_t,D,theta,volume,area,E_bend,E_elastic,dt,axis_angle,node_phase"; }

const char* legacy_time_series_header() { return "gamma_t,D,theta,volume,area,E_bend,E_elastic,dt"; }

namespace {
// v to `digits` significant digits, or "nan". A value so near the largest double that the
// rounding passes it (1.79769313486232e+308 > 1.7976931348623157e+308: no double, and no reader
// takes it) is written in its shortest exact form instead, so that every row reads back.
std::string cell(double v, int digits) {
  if (std::isnan(v)) return "nan";
  std::string s = fmt::format("{:.{}g}", v, digits);
  if (std::isfinite(v) && std::abs(v) > 1e308 && std::isinf(std::strtod(s.c_str(), nullptr))) s = fmt::format("{}", v);
  return s;
}
}  // namespace

std::string format_time_series_row(const TimeSeriesRow& r, bool legacy) {
  std::string s = fmt::format("{},{},{},{},{},{},{},{}", cell(r.t, 10), cell(r.D, 12), cell(r.theta, 12),
                              cell(r.volume, 15), cell(r.area, 15), cell(r.E_bend, 12), cell(r.E_elastic, 12),
                              cell(r.dt, 6));
  if (!legacy) s += fmt::format(",{},{}", cell(r.axis_angle, 12), cell(r.node_phase, 12));
  s += '\n';
  return s;
}

namespace {
// Reads every number the writer writes. std::stod would refuse a subnormal (below 2.2e-308: an
// energy of kS = 1/G at G = 1e308), for which strtod reports ERANGE; only an overflow, a number
// beyond the doubles, is refused.
double parse_number(const std::string& s, const std::string& source, std::int64_t line) {
  if (s == "nan") return std::numeric_limits<double>::quiet_NaN();
  if (!s.empty()) {
    char* end = nullptr;
    errno = 0;
    const double v = std::strtod(s.c_str(), &end);
    const bool overflow = errno == ERANGE && std::isinf(v);
    if (end == s.c_str() + s.size() && !overflow) return v;
  }
  throw Error(fmt::format("'{}' line {}: '{}' is not a number", source, line, s.substr(0, 40)));
}

TimeSeriesRow parse_row(const std::string& line, const std::string& source, std::int64_t n, bool legacy) {
  std::vector<double> v;
  std::istringstream s(line);
  for (std::string cell; std::getline(s, cell, ',');) v.push_back(parse_number(cell, source, n));
  const std::size_t columns = legacy ? 8 : 10;
  if (v.size() != columns)
    throw Error(fmt::format("'{}' line {}: {} columns, expected {}", source, n, v.size(), columns));
  const double nan = std::numeric_limits<double>::quiet_NaN();
  return {v[0], v[1], v[2], v[3], v[4], v[5], v[6], v[7], legacy ? nan : v[8], legacy ? nan : v[9]};
}

// Whether `header` is the older format's; throws for any other than the two.
bool legacy_header(const std::string& header, const std::string& source) {
  if (header == time_series_header()) return false;
  if (header == legacy_time_series_header()) return true;
  throw Error(fmt::format("'{}': header is '{}', expected '{}'", source, header.substr(0, 200), time_series_header()));
}

// The header line of text, checked; `pos` is set to the start of the first row. Returns whether
// it is the older format's.
bool check_header(const std::string& text, const std::string& source, std::size_t& pos) {
  const std::size_t end = text.find('\n');
  const bool legacy = legacy_header(text.substr(0, end), source);
  pos = end == std::string::npos ? text.size() : end + 1;
  return legacy;
}
}  // namespace

std::vector<TimeSeriesRow> parse_time_series(const std::string& text, const std::string& source) {
  std::istringstream in(text);
  std::string header;
  std::getline(in, header);
  const bool legacy = legacy_header(header, source);
  std::vector<TimeSeriesRow> rows;
  std::string line;
  for (std::int64_t n = 2; std::getline(in, line); ++n) rows.push_back(parse_row(line, source, n, legacy));
  return rows;
}

std::vector<TimeSeriesRow> read_time_series(const std::filesystem::path& path) {
  return parse_time_series(read_regular_file(path, "the time series"), path.string());
}

TimeSeriesFile::TimeSeriesFile(std::filesystem::path path, std::int64_t rows, bool legacy)
    : path_(std::move(path)), legacy_(legacy), rows_(rows) {
  out_.open(path_, std::ios::out | std::ios::app);
  if (!out_) throw Error(fmt::format("cannot append to '{}'", path_.string()));
}

TimeSeriesFile TimeSeriesFile::create(const std::filesystem::path& path) {
  AtomicFile f(path);
  f.stream() << time_series_header() << '\n';
  f.commit();
  return TimeSeriesFile(path, 0);
}

std::vector<TimeSeriesRow> read_time_series_head(const std::filesystem::path& path, std::int64_t rows,
                                                 std::size_t* bytes) {
  const std::string text = read_regular_file(path, "the time series");
  std::size_t pos = 0;
  const bool legacy = check_header(text, path.string(), pos);
  std::vector<TimeSeriesRow> kept;
  for (std::int64_t k = 0; k < rows; ++k) {
    const std::size_t end = text.find('\n', pos);
    if (end == std::string::npos)
      throw Error(fmt::format("'{}' has {} complete rows, the checkpoint needs {}", path.string(), k, rows));
    kept.push_back(parse_row(text.substr(pos, end - pos), path.string(), k + 2, legacy));
    pos = end + 1;
  }
  if (bytes) *bytes = pos;
  return kept;
}

TimeSeriesFile TimeSeriesFile::resume(const std::filesystem::path& path, std::int64_t rows) {
  std::size_t bytes = 0;
  read_time_series_head(path, rows, &bytes);
  const std::string text = read_regular_file(path, "the time series");
  if (text.size() < bytes) throw Error(fmt::format("'{}' changed while it was read", path.string()));
  std::size_t pos = 0;
  const bool legacy = check_header(text, path.string(), pos);
  AtomicFile f(path);
  f.stream().write(text.data(), static_cast<std::streamsize>(bytes));
  f.commit();
  return TimeSeriesFile(path, rows, legacy);
}

TimeSeriesFile TimeSeriesFile::append_to(const std::filesystem::path& path, std::int64_t rows) {
  return TimeSeriesFile(path, rows);
}

void TimeSeriesFile::append(const TimeSeriesRow& row) {
  out_ << format_time_series_row(row, legacy_);
  out_.flush();
  if (!out_) throw Error(fmt::format("error while writing '{}' (row {})", path_.string(), rows_ + 1));
  ++rows_;
}

}  // namespace bendlab
