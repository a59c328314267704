#pragma once
// Shape diagnostics of a capsule (paper section 4.1, docs/conventions.md §2): the ellipsoid with
// the same inertia tensor as the enclosed volume, its Taylor deformation D = (a - c)/(a + c) and
// its inclination theta in the shear plane (x-z; u_inf = gamma z e_x).
//
// The second moment M = int_V (y - c)(y - c)^T dV about the volume centroid c is a sum over the
// flat faces of the signed tetrahedra (c, x0, x1, x2) (divergence theorem; exact for the
// polyhedron): with p_k = x_k - c and det = p0 . (p1 x p2),
//   M_f = det / 120 * (sum_k p_k p_k^T + (sum_k p_k)(sum_k p_k)^T).
// The inertia tensor is I = tr(M) 1 - M; a solid ellipsoid of half axes (a, b, c) has
// M = V/5 diag(a^2, b^2, c^2), i.e. I = V/5 diag(b^2 + c^2, a^2 + c^2, a^2 + b^2), so the
// equivalent half axes are sqrt(5 m_k / V) for the eigenvalues m_k of M.
#include "bendlab/core/types.hpp"
#include "bendlab/mesh/topology.hpp"

namespace bendlab {

struct CapsuleShape {
  double volume = 0;
  Vec3 centroid = Vec3::Zero();
  Mat3 second_moment = Mat3::Zero();  ///< M about the centroid
  Mat3 inertia = Mat3::Zero();        ///< I = tr(M) 1 - M
  double a = 0, b = 0, c = 0;         ///< equivalent ellipsoid half axes, a >= b >= c
  Vec3 long_axis = Vec3::UnitX();     ///< unit eigenvector of the largest half axis
  /// Unit eigenvector of the shortest half axis c: of the smallest eigenvalue of M, i.e. of the
  /// LARGEST moment of inertia. For an oblate body (a disc, a red blood cell) this is the axis of
  /// symmetry; for a prolate one the axis of symmetry is long_axis (smallest moment of inertia).
  Vec3 short_axis = Vec3::UnitZ();
  double D = 0;                       ///< (a - c)/(a + c)
  double theta = 0;  ///< angle from e_x to long_axis projected on the x-z plane, radians in (-pi/2, pi/2]
};

CapsuleShape capsule_shape(const Topology& topology, const Points& x);

// Angles in the shear plane x-z, measured from e_z towards e_x: the sense in which the flow
// u = gamma z e_x (vorticity +gamma e_y) turns a body, so that a tumbling body's angle grows.
// A body turned by alpha about e_y carries e_z to (sin alpha, 0, cos alpha), at angle alpha.

/// The angle of the director d (d and -d are the same axis) projected on the shear plane,
/// atan2(d_x, d_z) folded into (-pi/2, pi/2].
double axis_angle(const Vec3& d);
/// The angle of the vector p projected on the shear plane, atan2(p_x, p_z) in (-pi, pi].
double shear_plane_phase(const Vec3& p);
/// The value equal to `raw` modulo `period` that lies nearest to `previous` (within period / 2):
/// how a time series follows an angle across its branch cuts.
double unwrap_angle(double previous, double raw, double period);

/// What the time series follows of a body's motion (docs/conventions.md §2, "Orientation and
/// tank-treading"), fixed by the initial shape:
///  - the axis of symmetry: the short axis (the largest moment of inertia) when the initial shape
///    is oblate-like (b - c > a - b: a disc, a red blood cell), else the long axis (a prolate body,
///    and a sphere, which shear stretches along its long axis), followed in the shear plane
///    (motion_angles);
///  - the marked node: of the initial positions, the node farthest from the centroid along the
///    shear-plane direction perpendicular to that axis, (cos alpha, 0, -sin alpha) for the axis at
///    angle alpha (an untilted disc: e_x), i.e. on the rim of a disc, in the shear plane; for a
///    shape without a distinct axis (a sphere: a - c within 1e-9 a) the direction is e_x. The
///    lowest index wins a tie.
struct MotionMarkers {
  bool short_axis = false;  ///< true: the axis is short_axis, false: long_axis
  int node = 0;
};
MotionMarkers motion_markers(const Topology& topology, const Points& x0);

/// The axis angle (period pi) and the node phase (shear_plane_phase of the marked node about the
/// centroid, period 2 pi) of shape s of x, folded into their ranges; a time series unwraps them
/// (unwrap_angle). The axis angle is that of the axis of the body's section by the shear plane:
/// the eigenvector of the x-z block of the second moment M with the smaller eigenvalue (short
/// axis: for an oblate body the largest moment of inertia about an axis in the plane) or the
/// larger (long axis). For a body symmetric about the shear plane this is the 3D axis whenever
/// that lies in the plane; unlike the 3D eigenvector it does not jump to e_y when a deformed
/// cell becomes thinner across the plane than within it (which a swinging red blood cell does).
struct MotionAngles {
  double axis = 0, node = 0;
};
MotionAngles motion_angles(const CapsuleShape& s, const Points& x, const MotionMarkers& m);

}  // namespace bendlab
