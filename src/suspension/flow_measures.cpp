#include "bendlab/suspension/flow_measures.hpp"

#include <fmt/format.h>

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

}  // namespace bendlab
