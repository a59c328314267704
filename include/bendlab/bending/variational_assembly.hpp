#pragma once
// The last step shared by the variational methods (C, D, E, ED): from the per-vertex normal, mean
// curvature H, Gaussian curvature K and Laplace-Beltrami of H, the force density of eq. (10),
//   f = 2 kB (lapH + 2 H (H^2 - K)) n        (Lap = div grad, H > 0 on a sphere: docs/conventions.md),
// and the node force of eq. (14), F = f * A_mixed.
#include "bendlab/bending/bending_method.hpp"

namespace bendlab {

/// Assembles the result of a variational method (C, D, E, ...) from its per-vertex normal, H, K
/// and lapH: f by eq. (10) with the docs/conventions.md sign, F = f * area by eq. (14). `area` is the
/// mixed area. Moves the inputs into the result; energy stays empty.
/// With c0 or ADE (bending_parameters.hpp, docs/conventions.md §5) f is the general force law
///   f = {2 kB [Lap H + 2 (H - c0)(H^2 + c0 H - K)] - lambda K} n,  lambda = alpha pi kB (M - M0) / A,
/// with the discrete M = sum_i H_i A_mixed_i; plain parameters take eq. (10)'s loop unchanged.
BendingResult assemble_variational_result(Points normal, Scalars H, Scalars K, Scalars lapH, Scalars area,
                                          const BendingParameters& p);

}  // namespace bendlab
