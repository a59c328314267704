#include "bendlab/mesh/mesh_io.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstring>
#include <fstream>
#include <set>

#include "bendlab/core/atomic_file.hpp"
#include "bendlab/core/file_input.hpp"
#include "mesh_io_detail.hpp"

namespace bendlab {
namespace io_detail {

std::string read_file(const std::filesystem::path& path) { return read_regular_file(path); }

std::string shown(std::string_view token) {
  constexpr std::size_t max_chars = 40;
  std::string s = "'";
  for (std::size_t i = 0; i < token.size() && i < max_chars; ++i) {
    const unsigned char c = static_cast<unsigned char>(token[i]);
    s += (c >= 0x20 && c < 0x7f) ? static_cast<char>(c) : '?';
  }
  if (token.size() > max_chars) s += "...";
  return s + "'";
}

void fail_at_line(const std::filesystem::path& path, long line, const std::string& what) {
  throw Error(fmt::format("cannot read '{}', line {}: {}", path.string(), line, what));
}

namespace {
std::string_view without_plus(std::string_view t) {
  // from_chars refuses a leading '+', which some writers put before exponents-free numbers too.
  if (t.size() > 1 && t[0] == '+' && t[1] != '-' && t[1] != '+') t.remove_prefix(1);
  return t;
}
}  // namespace

bool parse_double(std::string_view token, double& value) {
  token = without_plus(token);
  if (token.empty()) return false;
  const auto [end, ec] = std::from_chars(token.data(), token.data() + token.size(), value);
  return ec == std::errc() && end == token.data() + token.size();
}

bool parse_integer(std::string_view token, long long& value) {
  token = without_plus(token);
  if (token.empty()) return false;
  const auto [end, ec] = std::from_chars(token.data(), token.data() + token.size(), value);
  return ec == std::errc() && end == token.data() + token.size();
}

bool LineReader::next(std::vector<std::string_view>& tokens) {
  tokens.clear();
  while (pos_ < text_.size()) {
    std::size_t end = text_.find('\n', pos_);
    if (end == std::string_view::npos) end = text_.size();
    std::string_view line = text_.substr(pos_, end - pos_);
    pos_ = end + 1;
    ++line_;
    if (comment_ != '\0') {
      const std::size_t c = line.find(comment_);
      if (c != std::string_view::npos) line = line.substr(0, c);
    }
    std::size_t i = 0;
    const auto space = [](char ch) { return ch == ' ' || ch == '\t' || ch == '\r' || ch == '\v' || ch == '\f'; };
    while (i < line.size()) {
      while (i < line.size() && space(line[i])) ++i;
      const std::size_t b = i;
      while (i < line.size() && !space(line[i])) ++i;
      if (i > b) tokens.push_back(line.substr(b, i - b));
    }
    if (!tokens.empty()) return true;
  }
  return false;
}

void append_fan(const std::vector<int>& corners, std::vector<int>& triangles) {
  for (std::size_t k = 1; k + 1 < corners.size(); ++k) {
    triangles.push_back(corners[0]);
    triangles.push_back(corners[k]);
    triangles.push_back(corners[k + 1]);
  }
}

RawMesh make_raw_mesh(const std::vector<double>& xyz, const std::vector<int>& triangles) {
  RawMesh m;
  const auto n = static_cast<Eigen::Index>(xyz.size() / 3), f = static_cast<Eigen::Index>(triangles.size() / 3);
  m.positions = Eigen::Map<const Points>(xyz.data(), n, 3);
  m.faces = Eigen::Map<const Faces>(triangles.data(), f, 3);
  return m;
}

std::string xml_escaped(std::string_view text) {
  std::string s;
  for (const char c : text) {
    switch (c) {
      case '&': s += "&amp;"; break;
      case '<': s += "&lt;"; break;
      case '>': s += "&gt;"; break;
      case '"': s += "&quot;"; break;
      case '\'': s += "&apos;"; break;
      default: s += c;
    }
  }
  return s;
}

}  // namespace io_detail

namespace {

std::string lower_extension(const std::filesystem::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

std::string shown_extension(const std::filesystem::path& path) {
  const std::string ext = path.extension().string();
  return ext.empty() ? "none" : io_detail::shown(ext);
}

// Field names end up as PLY header tokens and XML attribute values, so they are kept to printable
// ASCII without whitespace or XML specials, and distinct (PLY properties are looked up by name).
void check_fields(const std::filesystem::path& path, const VertexFields& fields, Eigen::Index n) {
  std::set<std::string> used = {"x", "y", "z"};
  const auto use = [&](const std::string& name) {
    if (!used.insert(name).second)
      throw Error(fmt::format("cannot write '{}': field name '{}' is used twice (x, y, z and the components "
                              "name_x, name_y, name_z of vector fields count too)",
                              path.string(), name));
  };
  const auto check_name = [&](const std::string& name) {
    const bool ok = !name.empty() && std::all_of(name.begin(), name.end(), [](char c) {
      return c > 0x20 && c < 0x7f && !std::strchr("<>&\"'", c);
    });
    if (!ok)
      throw Error(fmt::format("cannot write '{}': bad field name {} (use printable characters without spaces "
                              "or < > & \" ')",
                              path.string(), io_detail::shown(name)));
  };
  for (const auto& [name, values] : fields.scalars) {
    check_name(name);
    use(name);
    if (values.size() != n)
      throw Error(fmt::format("cannot write '{}': field '{}' has {} values for {} vertices", path.string(), name,
                              values.size(), n));
  }
  for (const auto& [name, values] : fields.vectors) {
    check_name(name);
    use(name);
    for (const char* c : {"_x", "_y", "_z"}) use(name + c);
    if (values.rows() != n)
      throw Error(fmt::format("cannot write '{}': field '{}' has {} rows for {} vertices", path.string(), name,
                              values.rows(), n));
  }
}

}  // namespace

RawMesh read_raw_mesh(const std::filesystem::path& path) {
  const std::string ext = lower_extension(path);
  if (ext != ".off" && ext != ".obj" && ext != ".ply")
    throw Error(fmt::format("cannot read '{}': unknown mesh file extension {} (expected .off, .obj or .ply)",
                            path.string(), shown_extension(path)));
  const std::string bytes = io_detail::read_file(path);
  if (ext == ".off") return io_detail::read_off(path, bytes);
  if (ext == ".obj") return io_detail::read_obj(path, bytes);
  return io_detail::read_ply(path, bytes);
}

RawMesh parse_raw_mesh(const std::string& bytes, const std::string& format, const std::filesystem::path& name) {
  if (format == "off") return io_detail::read_off(name, bytes);
  if (format == "obj") return io_detail::read_obj(name, bytes);
  if (format == "ply") return io_detail::read_ply(name, bytes);
  throw Error(fmt::format("parse_raw_mesh: unknown format '{}' (expected off, obj or ply)", format));
}

TriMesh read_mesh(const std::filesystem::path& path, MeshOptions options) {
  RawMesh raw = read_raw_mesh(path);
  try {
    return TriMesh(std::move(raw.positions), raw.faces, options);
  } catch (const MeshError& e) {
    // Keep the problem (callers may branch on it) and add the file to the detail.
    const std::string prefix = std::string(to_string(e.problem())) + ": ";
    std::string detail = e.what();
    if (detail.compare(0, prefix.size(), prefix) == 0) detail.erase(0, prefix.size());
    throw MeshError(e.problem(), fmt::format("{} (in '{}')", detail, path.string()));
  }
}

void write_mesh(const std::filesystem::path& path, const Topology& topology, const Points& x,
                const VertexFields& fields) {
  const std::string ext = lower_extension(path);
  if (ext != ".off" && ext != ".obj" && ext != ".ply" && ext != ".vtp")
    throw Error(fmt::format("cannot write '{}': unknown mesh file extension {} (expected .off, .obj, .ply or .vtp)",
                            path.string(), shown_extension(path)));
  if (x.rows() != topology.num_vertices())
    throw Error(fmt::format("cannot write '{}': {} positions for {} vertices", path.string(), x.rows(),
                            topology.num_vertices()));
  if (ext == ".ply" || ext == ".vtp") check_fields(path, fields, x.rows());
  AtomicFile file(path, ext == ".ply");
  if (ext == ".off") io_detail::write_off(file.stream(), topology, x);
  if (ext == ".obj") io_detail::write_obj(file.stream(), topology, x);
  if (ext == ".ply") io_detail::write_ply(file.stream(), topology, x, fields);
  if (ext == ".vtp") io_detail::write_vtp(file.stream(), topology, x, fields);
  file.commit();
}

void write_pvd(const std::filesystem::path& path, const std::vector<std::pair<double, std::string>>& time_and_file) {
  for (const auto& [t, name] : time_and_file) {
    if (!std::isfinite(t))
      throw Error(fmt::format("cannot write '{}': time {} of '{}' is not finite", path.string(), t, name));
    if (name.empty() || std::any_of(name.begin(), name.end(), [](unsigned char c) { return c < 0x20 || c == 0x7f; }))
      throw Error(fmt::format("cannot write '{}': bad data file name {}", path.string(), io_detail::shown(name)));
  }
  AtomicFile file(path);
  io_detail::TextWriter w(file.stream());
  w.print("<?xml version=\"1.0\"?>\n");
  w.print("<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n  <Collection>\n");
  for (const auto& [t, name] : time_and_file)
    w.print("    <DataSet timestep=\"{:.17g}\" group=\"\" part=\"0\" file=\"{}\"/>\n", t, io_detail::xml_escaped(name));
  w.print("  </Collection>\n</VTKFile>\n");
  w.flush();
  file.commit();
}

}  // namespace bendlab
