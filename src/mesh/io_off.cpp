// OFF: reader and writer (format notes in bendlab/mesh/mesh_io.hpp).
#include <fmt/format.h>

#include <climits>

#include "mesh_io_detail.hpp"

namespace bendlab::io_detail {

namespace {

// "OFF" with the optional prefixes of its variants: ST (texture), C (colour), N (normal).
bool is_off_keyword(std::string_view t) {
  if (t.size() < 3 || t.substr(t.size() - 3) != "OFF") return false;
  t.remove_suffix(3);
  if (t.substr(0, 2) == "ST") t.remove_prefix(2);
  if (!t.empty() && t[0] == 'C') t.remove_prefix(1);
  if (!t.empty() && t[0] == 'N') t.remove_prefix(1);
  return t.empty();
}

}  // namespace

RawMesh read_off(const std::filesystem::path& path, std::string_view text) {
  LineReader r(text, '#');
  std::vector<std::string_view> tok;
  if (!r.next(tok)) fail_at_line(path, r.line(), "bad header: the file is empty (expected 'OFF')");
  if (!is_off_keyword(tok[0])) fail_at_line(path, r.line(), fmt::format("bad header: expected 'OFF', found {}", shown(tok[0])));
  if (tok.size() > 1 && tok[1] == "BINARY") fail_at_line(path, r.line(), "binary OFF is not supported");
  // The counts may follow the keyword on the same line.
  if (tok.size() > 1) {
    tok.erase(tok.begin());
  } else if (!r.next(tok)) {
    fail_at_line(path, r.line(), "truncated: the file ends before the counts line 'nv nf ne'");
  }
  if (tok.size() < 2 || tok.size() > 3)
    fail_at_line(path, r.line(), fmt::format("bad counts line: {} values, expected 'nv nf ne'", tok.size()));
  long long count[3] = {0, 0, 0};
  for (std::size_t k = 0; k < tok.size(); ++k)
    if (!parse_integer(tok[k], count[k]) || count[k] < 0 || count[k] > INT_MAX)
      fail_at_line(path, r.line(), fmt::format("bad counts line: {} is not a count", shown(tok[k])));
  const long long nv = count[0], nf = count[1];
  // Shortest possible lines: "0 0 0\n" and "3 0 1 2\n".
  if (6 * nv + 8 * nf > static_cast<long long>(text.size()) + 1)
    fail_at_line(path, r.line(),
                 fmt::format("wrong counts or truncated file: {} vertices and {} faces cannot fit in a file of {} bytes", nv, nf,
                             text.size()));

  std::vector<double> xyz;
  xyz.reserve(static_cast<std::size_t>(3 * nv));
  for (long long i = 0; i < nv; ++i) {
    if (!r.next(tok))
      fail_at_line(path, r.line(), fmt::format("truncated: the file ends after {} of {} vertices", i, nv));
    if (tok.size() < 3)
      fail_at_line(path, r.line(), fmt::format("vertex {} has {} values, expected x y z", i, tok.size()));
    for (int k = 0; k < 3; ++k) {
      double v;
      if (!parse_double(tok[k], v))
        fail_at_line(path, r.line(), fmt::format("vertex {}: non-numeric coordinate {}", i, shown(tok[k])));
      xyz.push_back(v);
    }
  }

  std::vector<int> triangles, corners;
  triangles.reserve(static_cast<std::size_t>(3 * nf));
  for (long long f = 0; f < nf; ++f) {
    if (!r.next(tok)) fail_at_line(path, r.line(), fmt::format("truncated: the file ends after {} of {} faces", f, nf));
    long long n;
    if (!parse_integer(tok[0], n))
      fail_at_line(path, r.line(), fmt::format("face {}: bad corner count {}", f, shown(tok[0])));
    if (n < 3) fail_at_line(path, r.line(), fmt::format("face {} has {} corners, at least 3 needed", f, n));
    if (static_cast<long long>(tok.size()) - 1 < n)
      fail_at_line(path, r.line(), fmt::format("face {} declares {} corners but lists {}", f, n, tok.size() - 1));
    corners.clear();
    for (long long k = 1; k <= n; ++k) {
      long long idx;
      if (!parse_integer(tok[k], idx))
        fail_at_line(path, r.line(), fmt::format("face {}: bad vertex index {}", f, shown(tok[k])));
      if (idx < 0) fail_at_line(path, r.line(), fmt::format("face {}: negative vertex index {}", f, idx));
      if (idx > INT_MAX) fail_at_line(path, r.line(), fmt::format("face {}: vertex index {} is too large", f, idx));
      corners.push_back(static_cast<int>(idx));
    }
    append_fan(corners, triangles);
  }
  if (r.next(tok))
    fail_at_line(path, r.line(),
                 fmt::format("wrong counts: data after the last face (the counts line declares {} vertices and {} faces)",
                             nv, nf));
  return make_raw_mesh(xyz, triangles);
}

void write_off(std::ostream& out, const Topology& topology, const Points& x) {
  TextWriter w(out);
  const Faces& F = topology.faces();
  w.print("OFF\n{} {} {}\n", x.rows(), F.rows(), topology.num_edges());
  for (Eigen::Index i = 0; i < x.rows(); ++i) w.print("{:.17g} {:.17g} {:.17g}\n", x(i, 0), x(i, 1), x(i, 2));
  for (Eigen::Index f = 0; f < F.rows(); ++f) w.print("3 {} {} {}\n", F(f, 0), F(f, 1), F(f, 2));
  w.flush();
}

}  // namespace bendlab::io_detail
