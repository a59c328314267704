// Wavefront OBJ: reader (v and f lines only) and writer.
#include <fmt/format.h>

#include <climits>

#include "mesh_io_detail.hpp"

namespace bendlab::io_detail {

RawMesh read_obj(const std::filesystem::path& path, std::string_view text) {
  LineReader r(text, '#');
  std::vector<std::string_view> tok;
  std::vector<double> xyz;
  std::vector<int> triangles, corners;
  long long face = 0;
  while (r.next(tok)) {
    if (tok[0] == "v") {
      if (tok.size() < 4)
        fail_at_line(path, r.line(), fmt::format("vertex {} has {} values, expected x y z", xyz.size() / 3, tok.size() - 1));
      for (int k = 1; k <= 3; ++k) {
        double v;
        if (!parse_double(tok[k], v))
          fail_at_line(path, r.line(), fmt::format("vertex {}: non-numeric coordinate {}", xyz.size() / 3, shown(tok[k])));
        xyz.push_back(v);
      }
    } else if (tok[0] == "f") {
      if (tok.size() < 4)
        fail_at_line(path, r.line(), fmt::format("face {} has {} corners, at least 3 needed", face, tok.size() - 1));
      const long long nv = static_cast<long long>(xyz.size() / 3);
      corners.clear();
      for (std::size_t k = 1; k < tok.size(); ++k) {
        // A corner is "v", "v/vt", "v//vn" or "v/vt/vn"; only v matters here.
        const std::string_view v = tok[k].substr(0, tok[k].find('/'));
        long long idx;
        if (!parse_integer(v, idx))
          fail_at_line(path, r.line(), fmt::format("face {}: bad vertex index {}", face, shown(tok[k])));
        if (idx == 0) fail_at_line(path, r.line(), fmt::format("face {}: vertex index 0 (OBJ indices start at 1)", face));
        // Negative indices count back from the last vertex read so far.
        const long long zero_based = idx > 0 ? idx - 1 : nv + idx;
        if (zero_based < 0)
          fail_at_line(path, r.line(),
                       fmt::format("face {}: relative index {} reaches before the first vertex ({} read so far)", face,
                                   idx, nv));
        if (zero_based > INT_MAX)
          fail_at_line(path, r.line(), fmt::format("face {}: vertex index {} is too large", face, idx));
        corners.push_back(static_cast<int>(zero_based));
      }
      append_fan(corners, triangles);
      ++face;
    }
  }
  return make_raw_mesh(xyz, triangles);
}

void write_obj(std::ostream& out, const Topology& topology, const Points& x) {
  TextWriter w(out);
  const Faces& F = topology.faces();
  w.print("# {} vertices, {} triangles\n", x.rows(), F.rows());
  for (Eigen::Index i = 0; i < x.rows(); ++i) w.print("v {:.17g} {:.17g} {:.17g}\n", x(i, 0), x(i, 1), x(i, 2));
  for (Eigen::Index f = 0; f < F.rows(); ++f) w.print("f {} {} {}\n", F(f, 0) + 1, F(f, 1) + 1, F(f, 2) + 1);
  w.flush();
}

}  // namespace bendlab::io_detail
