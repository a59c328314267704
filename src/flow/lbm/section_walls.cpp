#include "bendlab/flow/lbm/section_walls.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "bendlab/core/types.hpp"

namespace bendlab::lbm {

TubeWall::TubeWall(double radius) : radius_(radius) {
  if (!(radius > 0) || !std::isfinite(radius)) throw Error(fmt::format("tube radius {} must be finite and positive", radius));
}

bool TubeWall::solid(double y, double z) const { return y * y + z * z >= radius_ * radius_; }

double TubeWall::link_fraction(double y, double z, int cy, int cz) const {
  // |p + q d|^2 = R^2 with p inside (|p| < R) and p + d outside: the larger root lies in (0, 1].
  const double a = static_cast<double>(cy * cy + cz * cz);
  if (a == 0) throw Error("tube wall: a link along the axis never meets the wall");
  const double b = y * cy + z * cz;
  const double c = y * y + z * z - radius_ * radius_;
  const double disc = std::max(b * b - a * c, 0.0);
  // q = (-b + sqrt(disc)) / a, written without cancellation: c < 0 inside, so -b + sqrt(disc) > 0.
  const double s = std::sqrt(disc);
  const double q = b > 0 ? -c / (b + s) : (s - b) / a;
  return std::clamp(q, 1e-12, 1.0);
}

std::string TubeWall::describe() const { return fmt::format("tube of diameter {:g} dx", 2 * radius_); }

SlabWall::SlabWall(double half_height) : h_(half_height) {
  if (!(half_height > 0) || !std::isfinite(half_height)) throw Error(fmt::format("slab half-height {} must be finite and positive", half_height));
}

bool SlabWall::solid(double, double z) const { return std::abs(z) >= h_; }

double SlabWall::link_fraction(double, double z, int, int cz) const {
  if (cz == 0) throw Error("slab wall: a link parallel to the walls never meets them");
  const double wall = cz > 0 ? h_ : -h_;
  return std::clamp((wall - z) / cz, 1e-12, 1.0);
}

std::string SlabWall::describe() const { return fmt::format("channel of height {:g} dx", 2 * h_); }

}  // namespace bendlab::lbm
