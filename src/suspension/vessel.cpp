#include "bendlab/suspension/vessel.hpp"

#include <fmt/format.h>

#include <cmath>
#include <numbers>

namespace bendlab {

namespace {
void require_size(double v, const char* what) {
  if (!(v > 0) || !std::isfinite(v)) throw Error(fmt::format("vessel {} {} must be finite and positive", what, v));
}
}  // namespace

std::string to_string(VesselKind kind) {
  switch (kind) {
    case VesselKind::Tube: return "tube";
    case VesselKind::Channel: return "channel";
    case VesselKind::Box: return "box";
  }
  return "?";
}

Vessel::Vessel(VesselKind kind, double height, double width, double length)
    : kind_(kind), height_(height), width_(width), length_(length) {
  require_size(height, kind == VesselKind::Tube ? "diameter" : "height");
  require_size(width, "width");
  require_size(length, "length");
}

Vessel Vessel::tube(double diameter, double length) { return Vessel(VesselKind::Tube, diameter, diameter, length); }
Vessel Vessel::channel(double height, double width, double length) { return Vessel(VesselKind::Channel, height, width, length); }
Vessel Vessel::box(double height, double width, double length) { return Vessel(VesselKind::Box, height, width, length); }

Vec3 Vessel::period() const { return {length_, periodic(1) ? width_ : 0.0, 0.0}; }

Vec3 Vessel::minimum_image(Vec3 d) const {
  d.x() -= length_ * std::round(d.x() / length_);
  if (periodic(1)) d.y() -= width_ * std::round(d.y() / width_);
  return d;
}

double Vessel::wall_distance(const Vec3& p) const {
  if (kind_ == VesselKind::Tube) return 0.5 * height_ - std::hypot(p.y(), p.z());
  return 0.5 * height_ - std::abs(p.z());
}

Vec3 Vessel::wall_normal(const Vec3& p) const {
  if (kind_ == VesselKind::Tube) {
    const double r = std::hypot(p.y(), p.z());
    if (r == 0) return {0, 0, -1};  // every wall point is nearest: any inward normal
    return {0, -p.y() / r, -p.z() / r};
  }
  return {0, 0, p.z() >= 0 ? -1.0 : 1.0};
}

double Vessel::volume() const {
  if (kind_ == VesselKind::Tube) return 0.25 * std::numbers::pi * height_ * height_ * length_;
  return height_ * width_ * length_;
}

std::string Vessel::describe() const {
  if (kind_ == VesselKind::Tube) return fmt::format("tube {:g} across, {:g} long", height_, length_);
  return fmt::format("{} {:g} high, {:g} wide, {:g} long", to_string(kind_), height_, width_, length_);
}

}  // namespace bendlab
