#pragma once
// Walls parallel to the x axis of a lattice: a channel or tube whose cross-section in the (y, z)
// plane does not change along x (shared/spec/CELLS_IN_CHANNELS.md section 1). Every lattice row
// along x then lies wholly in the fluid or wholly in the solid, which lets the AA kernel of
// lattice.hpp keep its per-row plans: a row's links that reach into a solid row are bounced back
// for the whole row.
//
// Coordinates are the lattice's physical ones (Lattice::position: the box centred on the origin,
// nodes at half-integer offsets), in lattice units dx = 1. A link leaving the fluid point (y, z)
// along the projected direction (cy, cz) meets the wall at the fraction q of its length,
// 0 < q <= 1: the interpolated bounce-back of Bouzidi, Firdaouss & Lallemand (2001) uses q to
// place the wall between the nodes (q = 1/2 is the plain halfway bounce-back).
#include <memory>
#include <string>

namespace bendlab::lbm {

class SectionWalls {
 public:
  virtual ~SectionWalls() = default;
  /// Whether the row through (y, z) lies in the solid.
  virtual bool solid(double y, double z) const = 0;
  /// For a fluid point (y, z) whose neighbour (y + cy, z + cz) is solid: the fraction q in (0, 1]
  /// of the link where it meets the wall.
  virtual double link_fraction(double y, double z, int cy, int cz) const = 0;
  /// One line for messages and summaries ("tube of diameter 20 dx").
  virtual std::string describe() const = 0;
};

/// The circular tube r = sqrt(y^2 + z^2) < R about the x axis: a row is solid when its centre lies
/// at r >= R; the wall is the exact circle, cut by each link at its analytic intersection.
class TubeWall final : public SectionWalls {
 public:
  /// Throws bendlab::Error for a radius that is not finite and positive.
  explicit TubeWall(double radius);
  double radius() const { return radius_; }
  bool solid(double y, double z) const override;
  double link_fraction(double y, double z, int cy, int cz) const override;
  std::string describe() const override;

 private:
  double radius_;
};

/// The slit |z| < h between plane walls at z = -+h (y periodic): a channel as a cross-section, so
/// that its walls take the same path as a tube's (an immersed boundary's stencil may reach into the
/// solid rows, which rest). With h a whole number of dx / 2 from the box centre every wall lies
/// halfway between nodes (fraction 1/2) and the lattice steps bit for bit as between flat walls.
class SlabWall final : public SectionWalls {
 public:
  /// Throws bendlab::Error for a half-height that is not finite and positive.
  explicit SlabWall(double half_height);
  double half_height() const { return h_; }
  bool solid(double y, double z) const override;
  double link_fraction(double y, double z, int cy, int cz) const override;
  std::string describe() const override;

 private:
  double h_;
};

}  // namespace bendlab::lbm
