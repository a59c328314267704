#pragma once
// The integral of the Stokeslet over a triangle that contains the target at a corner, where the
// 7-point rule fails (the kernel is singular there): polar coordinates (rho, phi) centred on the
// target x0 (stokes_single_layer.hpp [118]). G dS = (I + e e^T) / rho * rho drho dphi, so the
// singularity cancels; with f linear along each ray the radial integral is exact,
// int_0^rho_max f drho = rho_max (f(x0) + f_edge(phi)) / 2, and the angle is integrated by
// Gauss-Legendre on equal sub-angles. The error is that of the angular rule alone, which the
// smooth integrand makes converge fast: on a right isosceles triangle 2 sub-angles of 8 points
// (the single layer's defaults) are within 1e-10 of the analytic value
// (tests/flow/test_singular_polar_integral.cpp).
#include <vector>

#include "bendlab/core/types.hpp"

namespace bendlab {

/// Integral over the triangle (x0, x1, x2), singular at x0, of f(y) . G(y, x0) dS(y),
/// G_kj = delta_kj / r + r_k r_j / r^3 (without the 1/(8 pi mu)), f linear with node values f0,
/// f1, f2; `subdivisions` equal sub-angles with the Gauss-Legendre rule (nodes, weights) on [0, 1]
/// (gauss_legendre_unit) on each.
Vec3 singular_polar_integral(const Vec3& x0, const Vec3& x1, const Vec3& x2, const Vec3& f0, const Vec3& f1,
                             const Vec3& f2, int subdivisions, const std::vector<double>& nodes,
                             const std::vector<double>& weights);

}  // namespace bendlab
