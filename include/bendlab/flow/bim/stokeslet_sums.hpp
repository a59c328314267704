#pragma once
// The regular sums of the single layer (stokes_single_layer.hpp): the Stokeslet G(y_k, x) . F_k
// summed over many source points y_k (density times weight F_k) for one target x, the loop
// that takes most of an evaluation. What the declarations do not say:
// - both are compiled for AVX-512, AVX2+FMA and baseline x86-64 (target_clones) and the
//   processor picks one at load time; stokeslet_sums.cpp is built with -fno-math-errno (so that
//   sqrt vectorises) and -ffp-contract=fast (fused multiply-adds), so the sums differ in the last
//   bits from the same arithmetic compiled elsewhere, and between instruction sets;
// - regular_sum is in double; mixed_sums in single precision, each range summed in kMixedBlock
//   float lanes relative to a centre and added in double: every range must hold a whole number
//   of blocks (pad with zero weights at a point away from every target).
#include <cstdint>

namespace bendlab {

/// mixed_sums' block: one AVX-512 register of floats, two of AVX2.
inline constexpr int kMixedBlock = 16;

/// out[0..2] = sum over k < nq of G(y_k, x) . F_k, y_k = (qx, qy, qz)[k], F_k = (fx, fy, fz)[k],
/// x = (xi, yi, zi), in double, G without the 1/(8 pi mu).
void regular_sum(double xi, double yi, double zi, const double* qx, const double* qy, const double* qz,
                 const double* fx, const double* fy, const double* fz, int nq, double* out);

/// A range of the single-precision arrays (a near leaf's 7-point points or a far cluster's
/// proxies), its points relative to a centre, and the target's offset (ox, oy, oz) from that centre.
struct MixedRange {
  int start, count;
  float ox, oy, oz;
};

/// out[0..2] = the sum over the ranges, each in float (kMixedBlock lanes) and added in double.
void mixed_sums(const MixedRange* ranges, int nranges, const float* qx, const float* qy, const float* qz,
                const float* fx, const float* fy, const float* fz, double* out);

}  // namespace bendlab
