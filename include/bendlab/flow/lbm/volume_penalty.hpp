#pragma once
// ESPResSo's volume-conservation force of the immersed-boundary capsule (ibm_volcons; technical
// note shared/spec/LBM_IBM.md section 4, after Dupin et al. eq. 9), used with kappa_V = 100 kappa_S
// in the paper's section 4.3.2. Every triangle t adds -kappa_V (V - V0)/V A_t n_t to each of its
// three vertices (A_t the full area, n_t the outward normal), V = 1/6 sum_t X_a.(X_b x X_c).
// Because sum_{t at a} A_t n_t = 3 dV/dX_a, the force is -3 kappa_V (V - V0)/V dV/dX_a, the exact
// negative gradient of the energy
//   E(V) = 3 kappa_V (V - V0 - V0 ln(V / V0)),   dE/dV = 3 kappa_V (V - V0) / V.
#include "bendlab/core/types.hpp"

namespace bendlab::lbm {

/// V = 1/6 sum_t X_a.(X_b x X_c) over counter-clockwise (outward) triangles.
double enclosed_volume(const Faces& faces, const Points& x);

/// Adds the volume force to `forces` (N x 3, resized and zeroed if its size differs) and returns
/// the energy E above. Throws bendlab::Error for V0 <= 0 or V <= 0.
double add_volume_penalty(const Faces& faces, const Points& x, double kappa_V, double V0, Points& forces);

}  // namespace bendlab::lbm
