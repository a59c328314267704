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
  double D = 0;                       ///< (a - c)/(a + c)
  double theta = 0;  ///< angle from e_x to long_axis projected on the x-z plane, radians in (-pi/2, pi/2]
};

CapsuleShape capsule_shape(const Topology& topology, const Points& x);

}  // namespace bendlab
