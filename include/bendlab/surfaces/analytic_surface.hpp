#pragma once
// Analytic reference surfaces (sphere, spheroid, RBC) and their exact differential geometry.
//
// Conventions (docs/conventions.md): outward unit normal n; H = (c1 + c2) / 2 > 0 on a sphere;
// K = c1 c2; lapH = div_S grad_S H; f = 2 kB (lapH + 2 H (H^2 - K)) n (eq. (10)).
// All surfaces are surfaces of revolution about the z axis, centred at the origin.
#include <memory>
#include <string>
#include <vector>

#include "bendlab/core/types.hpp"

namespace bendlab {

struct SurfaceValues {
  Vec3 normal = Vec3::Zero();  ///< outward unit normal
  double H = 0, K = 0, lapH = 0;
  double f_normal = 0;         ///< 2 kB (lapH + 2 H (H^2 - K))
  Vec3 f = Vec3::Zero();       ///< f_normal * normal
};

/// Maxima of |H|, |K|, |lapH|, |f| over the whole surface (not only over mesh nodes): the
/// denominators of the error measures of eq. (17).
struct SurfaceMaxima {
  double H = 0, K = 0, lapH = 0, f = 0;
};

/// Per-vertex values of a surface at many points (structure of arrays).
struct SurfaceFields {
  Points normal;
  Scalars H, K, lapH, f_normal;
  Points f;
};

class AnalyticSurface {
 public:
  virtual ~AnalyticSurface() = default;
  virtual std::string name() const = 0;
  /// Exact values at a point x lying on the surface (the point is identified by its position on
  /// the generating curve, so a node of a mesh mapped onto the surface gets the exact values at
  /// itself; regular at the poles).
  virtual SurfaceValues at(const Vec3& x, double kappa_b = 1.0) const = 0;
  /// Maxima over the whole surface, for the given kB (f scales with kB).
  virtual SurfaceMaxima maxima(double kappa_b = 1.0) const = 0;
  /// Maps points of the unit sphere onto this surface (the map the mesh families use).
  virtual Points map_from_unit_sphere(const Points& unit_sphere_points) const = 0;

  /// How far x lies from the surface point whose values at(x) returns (zero, to rounding, for a
  /// point on the surface). An upper bound of the distance to the surface, and the error of
  /// position that a comparison against at(x) carries.
  virtual double offset(const Vec3& x) const = 0;
  /// A length of the surface's size (its largest half-axis), for relative tolerances.
  virtual double size() const = 0;

  /// at() for every row of x.
  SurfaceFields evaluate(const Points& x, double kappa_b = 1.0) const;
};

/// The largest offset() over the rows of x, and the row where it occurs.
struct SurfaceOffset {
  double max = 0;
  Eigen::Index node = -1;
};
SurfaceOffset max_offset(const AnalyticSurface& surface, const Points& x);

/// Throws bendlab::Error, naming the node and its offset, when a row of x lies farther than
/// relative_tolerance * surface.size() from the surface: values compared against the surface
/// would then be compared at the wrong place. Non-finite rows are refused too.
void require_nodes_on_surface(const AnalyticSurface& surface, const Points& x, double relative_tolerance = 1e-6);

/// Sphere of radius R: H = 1/R, K = 1/R^2, lapH = 0, f = 0. Map: scale by R.
std::unique_ptr<AnalyticSurface> make_sphere(double radius = 1.0);
/// Spheroid x^2/a^2 + y^2/a^2 + z^2/c^2 = 1 (oblate a > c, prolate a < c). Map: scale (a, a, c).
std::unique_ptr<AnalyticSurface> make_spheroid(double a, double c);
/// Red blood cell of eq. (15) with large half-axis R and C0 = 0.2072, C1 = 2.0026, C2 = -1.1228.
/// Map: keep x, y; z = sign(z) R/2 sqrt(1 - rho^2) (C0 + C1 rho^2 + C2 rho^4), rho = |(x, y)| / R
/// (the unit-sphere points are first scaled by R).
std::unique_ptr<AnalyticSurface> make_rbc(double radius = 1.0);

/// By name: "sphere" (radius), "rbc" (radius), "oblate" / "prolate" (axes a, c; defaults 1, 0.5
/// and 0.5, 1), "spheroid" (axes). Throws bendlab::Error for an unknown name or bad parameters
/// (non-positive or non-finite, an oblate with a <= c, ...).
std::unique_ptr<AnalyticSurface> make_surface(const std::string& name, double radius = 1.0,
                                              std::vector<double> axes = {});

}  // namespace bendlab
