#include "bendlab/flow/bim/stokeslet_sums.hpp"

#include <cmath>

namespace bendlab {

namespace {

// One Stokeslet term G(y, x) . F added to (ux, uy, uz): (dx, dy, dz) = y - x and (fx, fy, fz) =
// F, the density times the quadrature weight, in the precision Real (double; float for
// tree_mixed, see the header). Inlined into the kernels below, each compiled three times
// (AVX-512, AVX2+FMA and baseline x86-64) and picked at run time, so the same binary runs
// everywhere and uses 8- or 4-wide doubles (16 or 8 floats) where the processor has them. The
// file is built with -fno-math-errno (so that sqrt vectorises) and -ffp-contract=fast (FMA).
template <typename Real>
[[gnu::always_inline]] inline void add_stokeslet(Real dx, Real dy, Real dz, Real fx, Real fy, Real fz, Real& ux,
                                                 Real& uy, Real& uz) {
  const Real s = Real(1) / std::sqrt(dx * dx + dy * dy + dz * dz);
  const Real fr = (fx * dx + fy * dy + fz * dz) * s * s * s;
  ux += fx * s + dx * fr;
  uy += fy * s + dy * fr;
  uz += fz * s + dz * fr;
}

}  // namespace

// Sum over the quadrature points y_k, k < nq, of the Stokeslet G(y_k, x) . f_k w_k for one target x.
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__) && !defined(__SANITIZE_ADDRESS__)
__attribute__((target_clones("arch=x86-64-v4", "arch=x86-64-v3", "default")))
#endif
void regular_sum(double xi, double yi, double zi, const double* __restrict qx, const double* __restrict qy,
                 const double* __restrict qz, const double* __restrict fx, const double* __restrict fy,
                 const double* __restrict fz, int nq, double* out) {
  double ux = 0, uy = 0, uz = 0;
#pragma omp simd reduction(+ : ux, uy, uz)
  for (int k = 0; k < nq; ++k) add_stokeslet(qx[k] - xi, qy[k] - yi, qz[k] - zi, fx[k], fy[k], fz[k], ux, uy, uz);
  out[0] = ux;
  out[1] = uy;
  out[2] = uz;
}

// tree_mixed: one target against a list of ranges of the single-precision arrays (a near leaf's
// 7-point points or a far cluster's proxies), each range's points relative to its box centre and
// (ox, oy, oz) the target's offset from that centre. Each range is summed in float in kMixedBlock
// partial sums (one vector register of floats with AVX-512, two with AVX2), which are then added
// to partial sums in double; the double lanes are added up once per target. Every range is a
// whole number of blocks (zero weights pad it), so the loop has no remainder.
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__) && !defined(__SANITIZE_ADDRESS__)
__attribute__((target_clones("arch=x86-64-v4", "arch=x86-64-v3", "default")))
#endif
void mixed_sums(const MixedRange* ranges, int nranges, const float* __restrict qx, const float* __restrict qy,
                const float* __restrict qz, const float* __restrict fx, const float* __restrict fy,
                const float* __restrict fz, double* out) {
  constexpr int L = kMixedBlock;
  double sx[L] = {}, sy[L] = {}, sz[L] = {};
  for (int r = 0; r < nranges; ++r) {
    const float xi = ranges[r].ox, yi = ranges[r].oy, zi = ranges[r].oz;
    float ax[L] = {}, ay[L] = {}, az[L] = {};
    // 64-bit indices: with 32-bit ones the vectoriser may pick narrower registers.
    const std::int64_t k1 = static_cast<std::int64_t>(ranges[r].start) + ranges[r].count;
    for (std::int64_t k0 = ranges[r].start; k0 < k1; k0 += L) {
#pragma omp simd
      for (std::int64_t l = 0; l < L; ++l) {
        const std::int64_t k = k0 + l;
        add_stokeslet(qx[k] - xi, qy[k] - yi, qz[k] - zi, fx[k], fy[k], fz[k], ax[l], ay[l], az[l]);
      }
    }
#pragma omp simd
    for (int l = 0; l < L; ++l) {
      sx[l] += ax[l];
      sy[l] += ay[l];
      sz[l] += az[l];
    }
  }
  double ux = 0, uy = 0, uz = 0;
  for (int l = 0; l < L; ++l) ux += sx[l], uy += sy[l], uz += sz[l];
  out[0] = ux;
  out[1] = uy;
  out[2] = uz;
}

}  // namespace bendlab
