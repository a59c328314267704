#pragma once
// The time series of a capsule run, timeseries.csv:
//   gamma_t,D,theta,volume,area,E_bend,E_elastic,dt,axis_angle,node_phase
// one row per accepted step; E_bend is `nan` where the bending method has no energy (or none).
// axis_angle and node_phase (radians, unwrapped: continuous over the run) are the orientation of
// the axis of symmetry in the shear plane and the phase of a marked membrane node about the
// centroid (capsule_shape.hpp, MotionMarkers). A file of the older 8-column format (without them)
// is still read (the angles NaN), and a run resumed in one keeps writing that format.
//
// The file is append-only during a run and flushed after every row; every write is checked (a
// failed write throws bendlab::Error naming the file). Rewrites (resume: keep the rows up to the
// checkpoint) go through a temporary file and an atomic rename, so the file is never half-written.
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "bendlab/core/types.hpp"

namespace bendlab {

struct TimeSeriesRow {
  double t = 0, D = 0, theta = 0, volume = 0, area = 0;
  double E_bend = 0;  ///< NaN where undefined
  double E_elastic = 0, dt = 0;
  double axis_angle = 0, node_phase = 0;  ///< NaN in a file of the older format
};

/// The header line (without newline).
const char* time_series_header();
/// The header of the older format, without axis_angle and node_phase.
const char* legacy_time_series_header();
/// One row as written, with its newline (legacy: the older format's 8 columns).
std::string format_time_series_row(const TimeSeriesRow& row, bool legacy = false);
/// All rows of a time series file; throws bendlab::Error naming the file and line for a missing
/// file, a wrong header or a malformed row.
std::vector<TimeSeriesRow> read_time_series(const std::filesystem::path& path);
/// The rows of the text of a time series file (what read_time_series() does after reading it);
/// `source` names it in errors. Throws bendlab::Error, and nothing else, for any malformed text.
std::vector<TimeSeriesRow> parse_time_series(const std::string& text, const std::string& source);
/// The first `rows` rows of the time series file at path, parsed as read_time_series parses every
/// row (the rows after them are not read: a killed run may have left half a row there). Throws
/// bendlab::Error naming the file and line for anything but a regular file, a wrong header, a
/// malformed row or fewer complete rows. `bytes`, if given, receives the length of the header and
/// those rows in the file.
std::vector<TimeSeriesRow> read_time_series_head(const std::filesystem::path& path, std::int64_t rows,
                                                 std::size_t* bytes = nullptr);

class TimeSeriesFile {
 public:
  /// A new file holding only the header (replacing any file at path, atomically).
  static TimeSeriesFile create(const std::filesystem::path& path);
  /// Keeps the header and the first `rows` rows of an existing file, byte for byte (atomic
  /// rewrite), then appends after them. Throws, before any change, as read_time_series_head does.
  static TimeSeriesFile resume(const std::filesystem::path& path, std::int64_t rows);
  /// Appends to path as it is (no header check); for tests of failing devices.
  static TimeSeriesFile append_to(const std::filesystem::path& path, std::int64_t rows = 0);

  /// Appends one row and flushes; throws bendlab::Error if the write fails.
  void append(const TimeSeriesRow& row);
  std::int64_t rows() const { return rows_; }
  /// Whether the file has the older header (and rows are written in that format).
  bool legacy() const { return legacy_; }
  const std::filesystem::path& path() const { return path_; }

 private:
  TimeSeriesFile(std::filesystem::path path, std::int64_t rows, bool legacy = false);
  std::filesystem::path path_;
  bool legacy_ = false;
  std::ofstream out_;
  std::int64_t rows_ = 0;
};

}  // namespace bendlab
