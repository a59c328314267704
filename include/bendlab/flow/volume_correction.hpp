#pragma once
// Volume conservation for the boundary integral method (paper section 4.3.1, after [68]).
//
// The discrete enclosed volume V = 1/6 sum_f x0 . (x1 x x2) has the exact gradient
//   a_i = dV/dx_i = 1/6 sum_{f at i} x_j x x_k = 1/3 sum_{f at i} A_f n_f,
// (i, j, k) the corners of f in counter-clockwise order starting at i; the two forms agree because
// the one-ring is closed (sum_f (x_k - x_j) = 0). The discrete flux of a node velocity field is
// therefore Q(u) = sum_i u_i . a_i = dV/dt.
#include "bendlab/core/types.hpp"
#include "bendlab/mesh/topology.hpp"

namespace bendlab {

/// a_i = dV/dx_i into `grad` (resized to N x 3).
void volume_gradient(const Topology& topology, const Points& x, Points& grad);

/// Q(u) = sum_i u_i . a_i.
double discrete_flux(const Points& grad, const Points& u);

/// Projects u (N x 3) onto the hyperplane Q(u) = 0: u <- u - (Q(u) / |a|^2) a, the nearest
/// field (in the Euclidean norm of R^3N) with zero discrete flux. Returns the removed Q(u).
double project_zero_flux(const Points& grad, Points& u);

/// Scales x about its volume centroid so that the enclosed volume becomes `target_volume`.
/// Returns the scale factor applied.
double rescale_to_volume(const Topology& topology, Points& x, double target_volume);

}  // namespace bendlab
