// PLY: reader (ascii, binary little and big endian, any scalar types) and binary little-endian writer.
#include <fmt/format.h>

#include <algorithm>
#include <bit>
#include <climits>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <optional>

#include "mesh_io_detail.hpp"

namespace bendlab::io_detail {

namespace {

enum class PlyType { Int8, UInt8, Int16, UInt16, Int32, UInt32, Float32, Float64 };

struct TypeInfo {
  const char* name;        // the traditional name
  const char* sized_name;  // the name with the bit count
  PlyType type;
  int size;
  bool integer;
  double min, max;  // range of an integer type
};

constexpr TypeInfo kTypes[] = {
    {"char", "int8", PlyType::Int8, 1, true, -128.0, 127.0},
    {"uchar", "uint8", PlyType::UInt8, 1, true, 0.0, 255.0},
    {"short", "int16", PlyType::Int16, 2, true, -32768.0, 32767.0},
    {"ushort", "uint16", PlyType::UInt16, 2, true, 0.0, 65535.0},
    {"int", "int32", PlyType::Int32, 4, true, -2147483648.0, 2147483647.0},
    {"uint", "uint32", PlyType::UInt32, 4, true, 0.0, 4294967295.0},
    {"float", "float32", PlyType::Float32, 4, false, 0.0, 0.0},
    {"double", "float64", PlyType::Float64, 8, false, 0.0, 0.0},
};

const TypeInfo& info(PlyType t) { return kTypes[static_cast<int>(t)]; }

std::optional<PlyType> type_from_name(std::string_view name) {
  for (const TypeInfo& t : kTypes)
    if (name == t.name || name == t.sized_name) return t.type;
  return std::nullopt;
}

struct Property {
  std::string name;
  bool list = false;
  PlyType count_type = PlyType::UInt8;  // lists only
  PlyType type = PlyType::Float64;      // the scalar, or the list's items
};

struct Element {
  std::string name;
  long long count = 0;
  std::vector<Property> properties;
  long header_line = 0;
};

enum class Format { Ascii, BinaryLittle, BinaryBig };

struct Header {
  Format format = Format::Ascii;
  std::vector<Element> elements;
  std::size_t data_start = 0;  // byte offset of the first byte after "end_header\n"
  long lines = 0;              // number of header lines
};

Header parse_header(const std::filesystem::path& path, std::string_view bytes) {
  Header h;
  bool have_format = false;
  std::size_t pos = 0;
  long line_no = 0;
  std::vector<std::string_view> tok;
  const auto fail = [&](const std::string& what) { fail_at_line(path, line_no, "bad header: " + what); };
  while (true) {
    if (pos >= bytes.size()) {
      if (line_no == 0) fail("the file is empty (expected 'ply')");
      fail("no 'end_header' line");
    }
    std::size_t end = bytes.find('\n', pos);
    if (end == std::string_view::npos) end = bytes.size();
    std::string_view line = bytes.substr(pos, end - pos);
    pos = std::min(end + 1, bytes.size());
    ++line_no;
    tok.clear();
    for (std::size_t i = 0; i < line.size();) {
      while (i < line.size() && (line[i] == ' ' || line[i] == '\t' || line[i] == '\r')) ++i;
      const std::size_t b = i;
      while (i < line.size() && line[i] != ' ' && line[i] != '\t' && line[i] != '\r') ++i;
      if (i > b) tok.push_back(line.substr(b, i - b));
    }
    if (line_no == 1) {
      if (tok.size() != 1 || tok[0] != "ply") fail(fmt::format("not a PLY file (the first line is {}, expected 'ply')", shown(line)));
      continue;
    }
    if (tok.empty() || tok[0] == "comment" || tok[0] == "obj_info") continue;
    if (tok[0] == "end_header") break;
    if (tok[0] == "format") {
      if (tok.size() != 3) fail("expected 'format <ascii|binary_little_endian|binary_big_endian> 1.0'");
      if (tok[1] == "ascii") h.format = Format::Ascii;
      else if (tok[1] == "binary_little_endian") h.format = Format::BinaryLittle;
      else if (tok[1] == "binary_big_endian") h.format = Format::BinaryBig;
      else fail(fmt::format("unknown format {}", shown(tok[1])));
      have_format = true;
    } else if (tok[0] == "element") {
      long long count;
      if (tok.size() != 3) fail("expected 'element <name> <count>'");
      if (!parse_integer(tok[2], count) || count < 0) fail(fmt::format("bad element count {}", shown(tok[2])));
      h.elements.push_back({std::string(tok[1]), count, {}, line_no});
    } else if (tok[0] == "property") {
      if (h.elements.empty()) fail("a property before the first element");
      Property p;
      if (tok.size() == 5 && tok[1] == "list") {
        const auto c = type_from_name(tok[2]), t = type_from_name(tok[3]);
        if (!c || !info(*c).integer) fail(fmt::format("bad list count type {}", shown(tok[2])));
        if (!t) fail(fmt::format("unknown type {}", shown(tok[3])));
        p = {std::string(tok[4]), true, *c, *t};
      } else if (tok.size() == 3 && tok[1] != "list") {
        const auto t = type_from_name(tok[1]);
        if (!t) fail(fmt::format("unknown type {}", shown(tok[1])));
        p = {std::string(tok[2]), false, PlyType::UInt8, *t};
      } else {
        fail("expected 'property <type> <name>' or 'property list <count type> <type> <name>'");
      }
      h.elements.back().properties.push_back(p);
    } else {
      fail(fmt::format("unknown keyword {}", shown(tok[0])));
    }
  }
  if (!have_format) fail("no 'format' line");
  h.data_start = pos;
  h.lines = line_no;
  return h;
}

// Where the mesh lives among the elements and properties.
struct Layout {
  int vertex = -1, face = -1;  // element indices
  int xyz[3] = {-1, -1, -1};   // property indices in the vertex element
  int corners = -1;            // property index of the face list
};

Layout find_layout(const std::filesystem::path& path, const Header& h) {
  Layout L;
  const auto fail = [&](long line, const std::string& what) { fail_at_line(path, line, "bad header: " + what); };
  for (int e = 0; e < static_cast<int>(h.elements.size()); ++e) {
    const Element& el = h.elements[e];
    int* slot = el.name == "vertex" ? &L.vertex : el.name == "face" ? &L.face : nullptr;
    if (!slot) continue;
    if (*slot >= 0) fail(el.header_line, fmt::format("a second '{}' element", el.name));
    *slot = e;
    if (el.count > INT_MAX) fail(el.header_line, fmt::format("{} '{}' elements are too many", el.count, el.name));
  }
  if (L.vertex < 0) fail(h.lines, "no 'vertex' element");
  const Element& v = h.elements[L.vertex];
  for (int p = 0; p < static_cast<int>(v.properties.size()); ++p)
    for (int k = 0; k < 3; ++k)
      if (v.properties[p].name == std::string(1, static_cast<char>('x' + k))) {
        if (v.properties[p].list) fail(v.header_line, fmt::format("vertex property '{}' is a list", v.properties[p].name));
        if (L.xyz[k] < 0) L.xyz[k] = p;
      }
  for (int k = 0; k < 3; ++k)
    if (L.xyz[k] < 0) fail(v.header_line, fmt::format("the vertex element has no property '{}'", static_cast<char>('x' + k)));
  if (L.face < 0) fail(h.lines, "no 'face' element");
  const Element& f = h.elements[L.face];
  for (int p = 0; p < static_cast<int>(f.properties.size()) && L.corners < 0; ++p)
    if (f.properties[p].name == "vertex_indices" || f.properties[p].name == "vertex_index") {
      if (!f.properties[p].list) fail(f.header_line, fmt::format("face property '{}' is not a list", f.properties[p].name));
      L.corners = p;
    }
  if (L.corners < 0) fail(f.header_line, "the face element has no list property 'vertex_indices' or 'vertex_index'");
  return L;
}

// Refuses counts that the data cannot hold, before anything is allocated: every binary value
// takes its size in bytes, every ascii value at least one character and one separator.
void check_counts(const std::filesystem::path& path, const Header& h, std::size_t data_bytes) {
  const bool ascii = h.format == Format::Ascii;
  unsigned long long budget = data_bytes + (ascii ? 1 : 0);  // the last ascii value needs no separator
  for (const Element& e : h.elements) {
    unsigned long long least = 0;
    for (const Property& p : e.properties) least += ascii ? 2 : info(p.list ? p.count_type : p.type).size;
    if (least == 0) continue;
    const auto count = static_cast<unsigned long long>(e.count);
    if (count > budget / least)
      fail_at_line(path, e.header_line,
                   fmt::format("wrong counts or truncated file: the header declares {} '{}' elements of at least {} bytes each, but only "
                               "{} bytes of data follow the header",
                               e.count, e.name, least, data_bytes));
    budget -= count * least;
  }
}

// The two data encodings behind one interface: begin(element, j), get(type, what) -> value,
// need(n, type) before n list items, end(), finish() at the end of the data.
class BinaryReader {
 public:
  BinaryReader(const std::filesystem::path& path, std::string_view bytes, std::size_t start, bool big_endian)
      : path_(path), bytes_(bytes), pos_(start), swap_(big_endian != (std::endian::native == std::endian::big)) {}

  void begin(const Element& e, long long j) { element_ = &e, index_ = j; }
  void end() {}

  double get(PlyType t, const std::string& what) {
    const int n = info(t).size;
    if (bytes_.size() - pos_ < static_cast<std::size_t>(n))
      fail(fmt::format("truncated: the file ends inside {}", what));
    unsigned char b[8];
    std::memcpy(b, bytes_.data() + pos_, n);
    if (swap_) std::reverse(b, b + n);
    pos_ += n;
    switch (t) {
      case PlyType::Int8: return load<std::int8_t>(b);
      case PlyType::UInt8: return load<std::uint8_t>(b);
      case PlyType::Int16: return load<std::int16_t>(b);
      case PlyType::UInt16: return load<std::uint16_t>(b);
      case PlyType::Int32: return load<std::int32_t>(b);
      case PlyType::UInt32: return load<std::uint32_t>(b);
      case PlyType::Float32: return load<float>(b);
      case PlyType::Float64: return load<double>(b);
    }
    return 0;
  }

  void need(long long n, PlyType t, const std::string& what) {
    if (static_cast<unsigned long long>(n) > (bytes_.size() - pos_) / info(t).size)
      fail(fmt::format("truncated: {} declares {} items but the file ends before them", what, n));
  }

  void finish() {
    if (pos_ != bytes_.size())
      throw Error(fmt::format("cannot read '{}', byte {}: wrong counts: {} bytes left over after the last element",
                              path_.string(), pos_, bytes_.size() - pos_));
  }

  [[noreturn]] void fail(const std::string& what) const {
    throw Error(fmt::format("cannot read '{}', byte {} ({} {} of {}): {}", path_.string(), pos_, element_->name, index_,
                            element_->count, what));
  }

 private:
  template <typename T>
  static double load(const unsigned char* b) {
    T v;
    std::memcpy(&v, b, sizeof v);
    return static_cast<double>(v);
  }

  const std::filesystem::path& path_;
  std::string_view bytes_;
  std::size_t pos_;
  bool swap_;
  const Element* element_ = nullptr;
  long long index_ = 0;
};

// Ascii data: one element per line (blank lines skipped), values separated by whitespace.
class AsciiReader {
 public:
  AsciiReader(const std::filesystem::path& path, std::string_view data, long header_lines)
      : path_(path), lines_(data, '\0'), offset_(header_lines) {}

  void begin(const Element& e, long long j) {
    element_ = &e, index_ = j, next_ = 0;
    if (!lines_.next(tok_)) fail("truncated: the file ends here");
  }
  void end() {
    if (next_ != tok_.size()) fail(fmt::format("wrong counts: {} values left over on the line", tok_.size() - next_));
  }

  double get(PlyType t, const std::string& what) {
    if (next_ >= tok_.size()) fail(fmt::format("too few values on the line: {} is missing", what));
    const std::string_view s = tok_[next_++];
    const TypeInfo& ti = info(t);
    if (ti.integer) {
      long long v;
      if (!parse_integer(s, v)) fail(fmt::format("{} {} is not an integer", what, shown(s)));
      if (v < ti.min || v > ti.max) fail(fmt::format("{} {} is out of range for {}", what, v, ti.name));
      return static_cast<double>(v);
    }
    double v;
    if (!parse_double(s, v)) fail(fmt::format("{} {} is not a number", what, shown(s)));
    return t == PlyType::Float32 ? static_cast<double>(static_cast<float>(v)) : v;
  }

  void need(long long n, PlyType, const std::string& what) {
    if (static_cast<unsigned long long>(n) > tok_.size() - next_)
      fail(fmt::format("{} declares {} items but the line has {} more values", what, n, tok_.size() - next_));
  }

  void finish() {
    if (lines_.next(tok_))
      throw Error(fmt::format("cannot read '{}', line {}: wrong counts: data after the last element", path_.string(),
                              offset_ + lines_.line()));
  }

  [[noreturn]] void fail(const std::string& what) const {
    throw Error(fmt::format("cannot read '{}', line {} ({} {} of {}): {}", path_.string(), offset_ + lines_.line(),
                            element_->name, index_, element_->count, what));
  }

 private:
  const std::filesystem::path& path_;
  LineReader lines_;
  long offset_;
  std::vector<std::string_view> tok_;
  std::size_t next_ = 0;
  const Element* element_ = nullptr;
  long long index_ = 0;
};

template <typename Reader>
RawMesh read_data(Reader& in, const Header& h, const Layout& L) {
  std::vector<double> xyz;
  std::vector<int> triangles, corners;
  xyz.reserve(static_cast<std::size_t>(3 * h.elements[L.vertex].count));
  triangles.reserve(static_cast<std::size_t>(3 * h.elements[L.face].count));
  for (int e = 0; e < static_cast<int>(h.elements.size()); ++e) {
    const Element& el = h.elements[e];
    if (el.properties.empty()) continue;  // nothing stored, whatever the count
    const bool is_vertex = e == L.vertex, is_face = e == L.face;
    for (long long j = 0; j < el.count; ++j) {
      in.begin(el, j);
      double x[3] = {0, 0, 0};
      for (int p = 0; p < static_cast<int>(el.properties.size()); ++p) {
        const Property& prop = el.properties[p];
        const std::string what = fmt::format("property '{}'", prop.name);
        if (!prop.list) {
          const double v = in.get(prop.type, what);
          if (is_vertex)
            for (int k = 0; k < 3; ++k)
              if (p == L.xyz[k]) x[k] = v;
          continue;
        }
        const double count = in.get(prop.count_type, "the item count of " + what);
        if (count < 0) in.fail(fmt::format("negative item count {} of {}", count, what));
        const auto n = static_cast<long long>(count);
        in.need(n, prop.type, what);
        const bool is_corners = is_face && p == L.corners;
        if (is_corners && n < 3) in.fail(fmt::format("a face with {} corners, at least 3 needed", n));
        corners.clear();
        for (long long k = 0; k < n; ++k) {
          const double v = in.get(prop.type, what);
          if (!is_corners) continue;
          if (!(v >= 0 && v <= INT_MAX && v == std::floor(v)))
            in.fail(fmt::format("bad vertex index {} in {}", v, what));
          corners.push_back(static_cast<int>(v));
        }
        if (is_corners) append_fan(corners, triangles);
      }
      in.end();
      if (is_vertex) xyz.insert(xyz.end(), x, x + 3);
    }
  }
  in.finish();
  return make_raw_mesh(xyz, triangles);
}

template <typename T>
void put_le(std::string& buf, T value) {
  char b[sizeof(T)];
  std::memcpy(b, &value, sizeof(T));
  if constexpr (std::endian::native == std::endian::big) std::reverse(b, b + sizeof(T));
  buf.append(b, sizeof(T));
}

}  // namespace

RawMesh read_ply(const std::filesystem::path& path, std::string_view bytes) {
  const Header h = parse_header(path, bytes);
  const Layout L = find_layout(path, h);
  check_counts(path, h, bytes.size() - h.data_start);
  if (h.format == Format::Ascii) {
    AsciiReader in(path, bytes.substr(h.data_start), h.lines);
    return read_data(in, h, L);
  }
  BinaryReader in(path, bytes, h.data_start, h.format == Format::BinaryBig);
  return read_data(in, h, L);
}

void write_ply(std::ostream& out, const Topology& topology, const Points& x, const VertexFields& fields) {
  const Faces& F = topology.faces();
  std::string buf = fmt::format("ply\nformat binary_little_endian 1.0\ncomment bendlab triangle mesh\n"
                                "element vertex {}\nproperty double x\nproperty double y\nproperty double z\n",
                                x.rows());
  for (const auto& [name, values] : fields.scalars) buf += fmt::format("property double {}\n", name);
  for (const auto& [name, values] : fields.vectors)
    buf += fmt::format("property double {0}_x\nproperty double {0}_y\nproperty double {0}_z\n", name);
  buf += fmt::format("element face {}\nproperty list uchar int vertex_indices\nend_header\n", F.rows());
  const auto flush = [&](bool always) {
    if (always || buf.size() > (1u << 16)) {
      out.write(buf.data(), static_cast<std::streamsize>(buf.size()));
      buf.clear();
    }
  };
  for (Eigen::Index i = 0; i < x.rows(); ++i) {
    for (int k = 0; k < 3; ++k) put_le(buf, x(i, k));
    for (const auto& [name, values] : fields.scalars) put_le(buf, values(i));
    for (const auto& [name, values] : fields.vectors)
      for (int k = 0; k < 3; ++k) put_le(buf, values(i, k));
    flush(false);
  }
  for (Eigen::Index f = 0; f < F.rows(); ++f) {
    put_le(buf, std::uint8_t{3});
    for (int k = 0; k < 3; ++k) put_le(buf, static_cast<std::int32_t>(F(f, k)));
    flush(false);
  }
  flush(true);
}

}  // namespace bendlab::io_detail
