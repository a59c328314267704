#pragma once
// The container of a suspension: where cells may be, how far a point is from the wall, and which
// axes are periodic (shared/spec/CELLS_IN_CHANNELS.md section 1; docs/conventions.md §6). Any
// consistent length unit (a flow run uses um at its interface, dx inside).
//
// The box is centred on the origin, the flow runs along x, periodic over `length`:
//   Tube     the circle y^2 + z^2 < (diameter/2)^2; y and z are bounded by the wall.
//   Channel  the slit |z| < height/2 between plane walls, periodic in y over `width`.
//   Box      no walls in y, periodic in x and y over `length` and `width`, plane walls at
//            |z| = height/2 (the shear box's moving walls; contact with them is the same).
// wall_distance is positive inside, zero on the wall, negative beyond it; wall_normal is the unit
// normal pointing from the nearest wall into the fluid.
#include <string>

#include "bendlab/core/types.hpp"

namespace bendlab {

enum class VesselKind { Tube, Channel, Box };

std::string to_string(VesselKind kind);

class Vessel {
 public:
  /// Throws bendlab::Error for a non-positive or non-finite size.
  static Vessel tube(double diameter, double length);
  static Vessel channel(double height, double width, double length);
  static Vessel box(double height, double width, double length);

  VesselKind kind() const { return kind_; }
  double length() const { return length_; }
  /// Tube: the diameter; else the periodic extent in y.
  double width() const { return width_; }
  /// Tube: the diameter; else the wall distance in z.
  double height() const { return height_; }
  double diameter() const { return height_; }

  bool periodic(int axis) const { return axis == 0 || (axis == 1 && kind_ != VesselKind::Tube); }
  /// The period along each axis (0 where the axis is not periodic).
  Vec3 period() const;
  /// d - p * round(d / p) along the periodic axes: the nearest image of a separation.
  Vec3 minimum_image(Vec3 d) const;

  double wall_distance(const Vec3& p) const;
  Vec3 wall_normal(const Vec3& p) const;
  /// The fluid volume of one period: pi D^2 L / 4 or H W L.
  double volume() const;
  std::string describe() const;

 private:
  Vessel(VesselKind kind, double height, double width, double length);
  VesselKind kind_;
  double height_, width_, length_;
};

}  // namespace bendlab
