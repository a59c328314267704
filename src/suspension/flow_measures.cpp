#include "bendlab/suspension/flow_measures.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace bendlab {

double tube_hematocrit(const Vessel& vessel, const CellRows& cells) {
  double v = 0;
  for (double c : cells.volume) v += c;
  return v / vessel.volume();
}

double discharge_hematocrit(const Vessel& vessel, const CellRows& cells, const Points& U, double flow_rate) {
  if (flow_rate == 0) return 0;
  double flux = 0;
  for (std::size_t c = 0; c < cells.first.size(); ++c) {
    if (cells.count[c] == 0) continue;
    const double u = U.col(0).segment(cells.first[c], cells.count[c]).mean();
    flux += cells.volume[c] * u;
  }
  return flux / (vessel.length() * flow_rate);
}

double cell_free_layer(const Vessel& vessel, const Points& x, double slice_width) {
  if (!(slice_width > 0) || !std::isfinite(slice_width)) throw Error(fmt::format("cell-free layer: slice width {} must be positive", slice_width));
  const double L = vessel.length();
  const int slices = std::max(1, static_cast<int>(std::floor(L / slice_width)));
  const int sides = vessel.kind() == VesselKind::Tube ? 1 : 2;
  const double none = std::numeric_limits<double>::infinity();
  std::vector<double> nearest(static_cast<std::size_t>(slices) * sides, none);
  for (Eigen::Index i = 0; i < x.rows(); ++i) {
    const Vec3 p = row(x, i);
    const double xw = p.x() - L * std::floor(p.x() / L + 0.5) + 0.5 * L;  // into [0, L)
    const int s = std::min(slices - 1, static_cast<int>(std::floor(xw / L * slices)));
    const int side = sides == 2 && p.z() > 0 ? 1 : 0;
    double& n = nearest[static_cast<std::size_t>(s) * sides + side];
    n = std::min(n, vessel.wall_distance(p));
  }
  double sum = 0;
  int count = 0;
  for (double n : nearest) {
    if (n == none) continue;
    sum += n;
    ++count;
  }
  return count > 0 ? sum / count : std::numeric_limits<double>::quiet_NaN();
}

std::vector<double> row_occupancy(const Vessel& vessel, const CellRows& cells, const Points& x, const LineGrid& grid) {
  const std::size_t lines = static_cast<std::size_t>(grid.ny) * grid.nz;
  std::vector<double> inside(lines, 0.0);
  if (cells.topology.size() != cells.first.size()) throw Error("row occupancy: every cell needs its topology");
  std::vector<std::vector<double>> crossings(lines);
  std::vector<std::size_t> touched;
  for (std::size_t c = 0; c < cells.first.size(); ++c) {
    const Faces& faces = cells.topology[c]->faces();
    const Eigen::Index base = cells.first[c];
    touched.clear();
    for (Eigen::Index f = 0; f < faces.rows(); ++f) {
      const Vec3 a = row(x, base + faces(f, 0)), b = row(x, base + faces(f, 1)), d = row(x, base + faces(f, 2));
      const double ylo = std::min({a.y(), b.y(), d.y()}), yhi = std::max({a.y(), b.y(), d.y()});
      const double zlo = std::min({a.z(), b.z(), d.z()}), zhi = std::max({a.z(), b.z(), d.z()});
      const int j0 = std::max(0, static_cast<int>(std::ceil((ylo - grid.y0) / grid.dy)));
      const int j1 = std::min(grid.ny - 1, static_cast<int>(std::floor((yhi - grid.y0) / grid.dy)));
      const int k0 = std::max(0, static_cast<int>(std::ceil((zlo - grid.z0) / grid.dz)));
      const int k1 = std::min(grid.nz - 1, static_cast<int>(std::floor((zhi - grid.z0) / grid.dz)));
      // Barycentric coordinates of the line's (y, z) in the triangle's projection.
      const double det = (b.y() - a.y()) * (d.z() - a.z()) - (d.y() - a.y()) * (b.z() - a.z());
      if (det == 0) continue;  // seen edge-on: no line crosses it inside
      for (int k = k0; k <= k1; ++k) {
        for (int j = j0; j <= j1; ++j) {
          const double py = grid.y0 + j * grid.dy - a.y(), pz = grid.z0 + k * grid.dz - a.z();
          const double u = (py * (d.z() - a.z()) - (d.y() - a.y()) * pz) / det;
          const double v = ((b.y() - a.y()) * pz - py * (b.z() - a.z())) / det;
          if (u < 0 || v < 0 || u + v > 1) continue;
          const std::size_t l = static_cast<std::size_t>(j) + static_cast<std::size_t>(grid.ny) * k;
          if (crossings[l].empty()) touched.push_back(l);
          crossings[l].push_back(a.x() + u * (b.x() - a.x()) + v * (d.x() - a.x()));
        }
      }
    }
    for (const std::size_t l : touched) {
      std::vector<double>& cx = crossings[l];
      if (cx.size() % 2 == 0) {
        std::sort(cx.begin(), cx.end());
        for (std::size_t i = 0; i + 1 < cx.size(); i += 2) inside[l] += cx[i + 1] - cx[i];
      }
      cx.clear();
    }
  }
  for (double& v : inside) v = std::min(1.0, v / vessel.length());
  return inside;
}

}  // namespace bendlab
