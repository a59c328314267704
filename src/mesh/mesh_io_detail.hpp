#pragma once
// Shared pieces of the mesh readers and writers (src/mesh/io_*.cpp); not part of the public API.
#include <fmt/format.h>

#include <filesystem>
#include <iterator>
#include <ostream>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "bendlab/mesh/mesh_io.hpp"

namespace bendlab::io_detail {

/// The whole file as bytes. Throws bendlab::Error for a missing, unreadable or directory path.
std::string read_file(const std::filesystem::path& path);

/// A token shown in a message: quoted, cut to a few dozen characters, non-printables as '?', so
/// that the message stays one readable line whatever the file holds.
std::string shown(std::string_view token);

/// "cannot read 'PATH', line N: WHAT" as a bendlab::Error.
[[noreturn]] void fail_at_line(const std::filesystem::path& path, long line, const std::string& what);

/// Whole-token number parsing ('+' accepted before a number). False when the token is not a
/// number or out of range.
bool parse_double(std::string_view token, double& value);
bool parse_integer(std::string_view token, long long& value);

/// Splits text into lines (\n, with a trailing \r dropped) and lines into whitespace-separated
/// tokens. With a comment character, everything from it to the end of the line is dropped.
class LineReader {
 public:
  LineReader(std::string_view text, char comment) : text_(text), comment_(comment) {}
  /// Next line that has at least one token; false at the end of the text.
  bool next(std::vector<std::string_view>& tokens);
  /// 1-based number of the line last returned (or of the last line, at the end).
  long line() const { return line_; }

 private:
  std::string_view text_;
  char comment_;
  std::size_t pos_ = 0;
  long line_ = 0;
};

/// Appends the fan triangulation (c0, c_k, c_{k+1}) of a polygon with >= 3 corners.
void append_fan(const std::vector<int>& corners, std::vector<int>& triangles);

/// Positions (3 per vertex) and triangle indices (3 per triangle) as a RawMesh.
RawMesh make_raw_mesh(const std::vector<double>& xyz, const std::vector<int>& triangles);

RawMesh read_off(const std::filesystem::path& path, std::string_view text);
RawMesh read_obj(const std::filesystem::path& path, std::string_view text);
RawMesh read_ply(const std::filesystem::path& path, std::string_view bytes);

/// Text output through an in-memory buffer handed to the stream in large pieces.
class TextWriter {
 public:
  explicit TextWriter(std::ostream& out) : out_(out) {}
  template <typename... Args>
  void print(fmt::format_string<Args...> format, Args&&... args) {
    fmt::format_to(std::back_inserter(buffer_), format, std::forward<Args>(args)...);
    if (buffer_.size() > (1u << 16)) flush();
  }
  void flush() {
    out_.write(buffer_.data(), static_cast<std::streamsize>(buffer_.size()));
    buffer_.clear();
  }

 private:
  std::ostream& out_;
  fmt::memory_buffer buffer_;
};

/// Text with the five XML special characters replaced by entities.
std::string xml_escaped(std::string_view text);

// Writers: the caller has checked x against the topology and the fields (check_fields) and
// commits the stream.
void write_off(std::ostream& out, const Topology& topology, const Points& x);
void write_obj(std::ostream& out, const Topology& topology, const Points& x);
void write_ply(std::ostream& out, const Topology& topology, const Points& x, const VertexFields& fields);
void write_vtp(std::ostream& out, const Topology& topology, const Points& x, const VertexFields& fields);

}  // namespace bendlab::io_detail
