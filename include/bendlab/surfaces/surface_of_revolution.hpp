#pragma once
// The one concrete AnalyticSurface: a surface of revolution about z whose generating curve, in
// the polar angle t of the unit-sphere point that maps onto it, reads
//
//     r(t) = A sin t,    z(t) = cos t * Z(sin^2 t),    Z(w) = sum_k z_k w^k > 0 on [0, 1].
//
// Sphere: A = R, Z = R.  Spheroid: A = a, Z = c.  RBC of eq. (15): A = R,
// Z(w) = R/2 (C0 + C1 w + C2 w^2), because sqrt(1 - rho^2) = |cos t| with rho = sin t and the
// sign of z follows cos t.
//
// Writing the curve this way makes z'(t) = sin t * B(t) with B = -Z + 2 cos^2 t Z'(w) explicitly,
// so the azimuthal curvature -z' / (r s') = -B / (A s') needs no division by r = 0 at the poles.
// Signs (docs/conventions.md): outward normal, H = (c1 + c2)/2 > 0 on a sphere, lapH = div_S grad_S H.
#include <mutex>
#include <vector>

#include "bendlab/surfaces/analytic_surface.hpp"

namespace bendlab {

/// The RBC shape constants of eq. (15).
inline constexpr double kRbcC0 = 0.2072;
inline constexpr double kRbcC1 = 2.0026;
inline constexpr double kRbcC2 = -1.1228;

/// Everything known at one point of the generating curve (azimuth-independent).
struct MeridianValues {
  double r = 0, z = 0;      ///< position on the curve
  double ds_dt = 0;         ///< arclength speed s' = sqrt(r'^2 + z'^2)
  double n_r = 0, n_z = 0;  ///< outward unit normal of the curve, (-z', r') / s'
  double c1 = 0;            ///< meridional principal curvature
  double c2 = 0;            ///< azimuthal principal curvature
  double H = 0, K = 0, lapH = 0;
  /// f_normal / kB = 2 (lapH + 2 H (H^2 - K)), eq. (10).
  double f_normal_per_kb() const { return 2.0 * (lapH + 2.0 * H * (H * H - K)); }
};

class SurfaceOfRevolution : public AnalyticSurface {
 public:
  /// How map_from_unit_sphere places a unit-sphere point.
  enum class SphereMap {
    Scale,      ///< (A x, A y, Z z): the linear map of a sphere or spheroid (Z constant)
    RbcHeight,  ///< keep A (x, y), z = sign(z) sqrt(1 - rho^2) Z(rho^2): the RBC map of eq. (15)
  };

  /// z_coeffs: the coefficients z_0, z_1, ... of Z(w). Throws bendlab::Error unless A > 0 and
  /// Z > 0 on [0, 1] (both finite).
  SurfaceOfRevolution(std::string name, double A, std::vector<double> z_coeffs, SphereMap map);

  std::string name() const override { return name_; }
  SurfaceValues at(const Vec3& x, double kappa_b = 1.0) const override;
  SurfaceMaxima maxima(double kappa_b = 1.0) const override;
  Points map_from_unit_sphere(const Points& unit_sphere_points) const override;
  double offset(const Vec3& x) const override;
  double size() const override;

  /// Values on the curve at polar parameter t in [0, pi].
  MeridianValues meridian(double t) const;
  /// The same from (sin t, cos t), which need not be normalised (only the direction counts);
  /// this is what at() uses, so that points next to either pole keep full accuracy.
  MeridianValues meridian_sc(double sin_t, double cos_t) const;
  /// The polar parameter t in [0, pi] of a point on (or next to) the surface.
  double parameter_of(const Vec3& x) const;
  /// Values at polar parameter t and azimuth phi (the point A sin t (cos phi, sin phi), z(t)).
  SurfaceValues at_angles(double t, double phi, double kappa_b = 1.0) const;

  double radial_scale() const { return A_; }
  /// Z(w).
  double height_factor(double w) const;
  /// Area int dA and integrated mean curvature M = int H dA (Gauss-Legendre in t, converged to
  /// rounding for the shapes here).
  struct Integrals {
    double area = 0, mean_curvature = 0;
  };
  Integrals integrals() const;
  /// max over the surface of |f_n| of the force law with spontaneous curvature c0 and ADE
  /// coefficient lambda (bending/bending_parameters.hpp, docs/conventions.md §5).
  double max_force_density(double c0, double kappa_b, double lambda) const;

 private:
  SurfaceValues from_meridian(const MeridianValues& m, double cos_phi, double sin_phi,
                              double kappa_b) const;

  std::string name_;
  double A_;
  std::vector<double> zc_;  // Z(w) coefficients, lowest order first
  SphereMap map_;
  mutable std::once_flag maxima_once_;
  mutable SurfaceMaxima maxima_unit_kb_;  // maxima for kB = 1
};

}  // namespace bendlab
