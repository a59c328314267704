#pragma once
// Differential geometry of a graph w = h(u, v) at the origin of its chart, from the height
// derivatives there (Method M, ../shared/spec/METHOD_M.md step 5; docs/conventions.md §1 for the
// signs). The chart is a right-handed orthonormal frame (t1, t2, n0); the surface is
// X(u, v) = x0 + u t1 + v t2 + h(u, v) n0 with h(0, 0) = 0, and its normal is taken on the side of n0.
//
// With p = h_u, q = h_v, r = h_uu, s = h_uv, t = h_vv and W^2 = 1 + p^2 + q^2:
//   n    = (-p, -q, 1) / W                                  (components in t1, t2, n0)
//   K    = (r t - s^2) / W^4
//   H    = -N / (2 W^3),  N = (1 + q^2) r - 2 p q s + (1 + p^2) t      (H = 1/R > 0 on a sphere
//          seen from outside: the surface bends away from n)
//   Lap_S H = g^ab (H_ab - Gamma^c_ab H_c) = g^ab H_ab - (g^ab h_ab) (grad h . grad H) / W^2,
// with g^ab = delta_ab - h_a h_b / W^2 and, for a graph, Gamma^c_ab = g^cd h_d h_ab, g^cd h_d = h_c / W^2.
// H_a and H_ab at the origin are the first and second derivatives of the expression for H, which
// involve the height derivatives up to order 4: they are carried through the products and the
// power W^-3 by second-order jet arithmetic (SecondOrderJet below), not written out by hand.
#include "bendlab/core/types.hpp"

namespace bendlab {

/// The height derivatives d^(a+b) h / du^a dv^b at the chart's origin, orders 1 to 4.
struct HeightDerivatives {
  double u = 0, v = 0;                                  ///< h_u, h_v
  double uu = 0, uv = 0, vv = 0;                        ///< h_uu, h_uv, h_vv
  double uuu = 0, uuv = 0, uvv = 0, vvv = 0;            ///< third derivatives
  double uuuu = 0, uuuv = 0, uuvv = 0, uvvv = 0, vvvv = 0;  ///< fourth derivatives
};

/// A function of (u, v) known to second order at a point: value, gradient and Hessian.
struct SecondOrderJet {
  double f = 0, u = 0, v = 0, uu = 0, uv = 0, vv = 0;
};
SecondOrderJet operator+(const SecondOrderJet& a, const SecondOrderJet& b);
SecondOrderJet operator-(const SecondOrderJet& a, const SecondOrderJet& b);
SecondOrderJet operator*(const SecondOrderJet& a, const SecondOrderJet& b);  ///< Leibniz to order 2
SecondOrderJet operator*(double c, const SecondOrderJet& a);
SecondOrderJet operator+(double c, const SecondOrderJet& a);
/// a^e for a jet with a.f > 0 (chain rule to order 2).
SecondOrderJet pow(const SecondOrderJet& a, double e);

/// What the graph's geometry gives at the origin.
struct GraphCurvatures {
  Vec3 normal_local = Vec3::Zero();  ///< unit normal, components in (t1, t2, n0)
  double H = 0, K = 0, lapH = 0;     ///< mean curvature, Gaussian curvature, Laplace-Beltrami of H
};

/// n, H, K and Lap_S H at the origin of the graph with these height derivatives (header formulas).
GraphCurvatures graph_curvatures(const HeightDerivatives& d);

}  // namespace bendlab
