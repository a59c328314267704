#pragma once
// The quadrature rules of the boundary integral (stokes_single_layer.hpp): the 7-point rule on a
// triangle, for every triangle that does not contain the target, and Gauss-Legendre on [0, 1],
// for the angle of the singular polar integral (singular_polar_integral.hpp).
// - The 7-point rule (Strang-Fix / Dunavant) integrates polynomials of total degree <= 5 exactly,
//   not of degree 6 (tests/flow/test_triangle_quadrature.cpp); its weights sum to 1, so a
//   triangle's integral is the weighted sum times the area.
// - Gauss-Legendre with n points is exact to degree 2n - 1; the nodes are found by Newton's
//   iteration on P_n at each call (to 1e-16), so callers compute them once and keep them.
#include <vector>

namespace bendlab {

/// The 7-point degree-5 rule on a triangle: barycentric coordinates (of corners 0, 1, 2) and
/// weights summing to 1 (multiply by the area).
struct TriangleRule7 {
  static constexpr int size = 7;
  double bary[7][3];
  double weight[7];
};
const TriangleRule7& triangle_rule7();

/// Gauss-Legendre nodes and weights on [0, 1] (n >= 1).
void gauss_legendre_unit(int n, std::vector<double>& nodes, std::vector<double>& weights);

}  // namespace bendlab
