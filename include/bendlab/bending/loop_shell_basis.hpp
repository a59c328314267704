#pragma once
// Method S (paper section 2.5): the shape functions of one Loop subdivision patch, and the
// triangle quadrature rules the method integrates with. Derivation: shared/spec/METHOD_S.md
// sections 1-2 (Cirak, Ortiz and Schroeder 2000; Stam 1998).
//
// A patch is one triangle (EV, A, B), counter-clockwise seen from outside, parametrised by
// barycentrics (u, v, w), u = 1 - v - w: u = 1 at EV (the corner that may be extraordinary,
// valence N != 6), v = 1 at A, w = 1 at B. Its N + 6 control points, in the local order used
// throughout Method S:
//   0 = EV; 1 = A; N = B; 2 .. N-1 = the EV's ring from A away from B (clockwise);
//   N+1 = the vertex opposite EV across AB; N+2, N+3 = ring of A after N+1 (A's ring read
//   counter-clockwise: EV, 2, N+3, N+2, N+1, B); N+4, N+5 = ring of B after N+1 (B's ring read
//   counter-clockwise: EV, A, N+1, N+4, N+5, N-1).
// For N = 6 the patch is the 12 quartic box splines; otherwise it is evaluated exactly by
// subdividing towards the EV (Cirak's method with the subdivision matrix of Loop's original
// weights, beta_N = (5/8 - (3/8 + cos(2 pi / N) / 4)^2) / N).
#include <vector>

#include <Eigen/Dense>

namespace bendlab::loop_shell {

/// Rows of a patch basis: the shape functions and their derivatives in theta = (v, w).
enum BasisRow { kValue = 0, kDv = 1, kDw = 2, kDvv = 3, kDvw = 4, kDww = 5 };
/// 6 x (N + 6): row r = BasisRow r of every control point's shape function (local order).
using PatchBasis = Eigen::Matrix<double, 6, Eigen::Dynamic>;

/// Loop's original beta_N (beta_6 = 1/16).
double loop_beta(int valence);
/// Weight of each ring vertex in the limit-position mask, chi = 1 / (N + 3 / (8 beta_N))
/// (chi_6 = 1/12); the centre weighs 1 - N chi.
double limit_ring_weight(int valence);

/// The 12 quartic box splines in Cirak's numbering 1..12 (columns 0..11; METHOD_S.md section 1)
/// and their derivatives in (v, w), at any (v, w) of the reference triangle.
Eigen::Matrix<double, 6, 12> box_splines(double v, double w);

/// Lattice offsets (a, b) of Cirak's nodes 1..12: node k sits at a e_v + b e_w from node 4.
const std::vector<std::pair<int, int>>& box_spline_offsets();

/// Local order -> Cirak number (0-based) for N = 6: [3, 6, 2, 0, 1, 4, 7, 10, 9, 5, 11, 8].
const std::vector<int>& regular_local_to_cirak();

/// The (N + 12) x (N + 6) subdivision matrix A-bar of a patch with an EV of valence N
/// (METHOD_S.md section 2; its first N + 6 rows are A).
Eigen::MatrixXd subdivision_matrix(int valence);

/// The basis of a patch with EV valence N at (v, w), in local order. For N = 6 any point of the
/// triangle; for N != 6 any point but the EV itself (v = w = 0), where only the limit masks are
/// defined (throws bendlab::Error). Throws for N < 3 or a point outside the triangle.
PatchBasis patch_basis(int valence, double v, double w);

/// The same by exact subdivision towards the EV, for any N >= 3 (N = 6 included, where it must
/// reproduce the box splines) and (v, w) != (0, 0).
PatchBasis patch_basis_by_subdivision(int valence, double v, double w);

/// A symmetric quadrature rule on the reference triangle: points (v, w) and weights summing to
/// 1 (multiply by the area, 1/2 in (v, w), to integrate).
struct TriangleRule {
  std::vector<double> v, w, weight;
  int size() const { return static_cast<int>(weight.size()); }
};
/// Dunavant's symmetric rules with 1, 3, 6, 7 or 12 points (exact to degree 1, 2, 4, 5, 6).
/// Throws bendlab::Error for another count.
TriangleRule dunavant_rule(int points);

}  // namespace bendlab::loop_shell
