#include "bendlab/flow/bim/chebyshev_moments.hpp"

#include <algorithm>

namespace bendlab {

void chebyshev_moments_reference(const double* S, const double* centre, int q, const double* sx, const double* sy,
                                 const double* sz, const double* sfx, const double* sfy, const double* sfz, int count,
                                 double* mx, double* my, double* mz) {
  double T[3][9];
  for (int k = 0; k < count; ++k) {
    const double r[3] = {sx[k] - centre[0], sy[k] - centre[1], sz[k] - centre[2]};
    for (int d = 0; d < 3; ++d) {
      const double s = S[d] * r[0] + S[3 + d] * r[1] + S[6 + d] * r[2];
      T[d][0] = 1;
      T[d][1] = s;
      for (int a = 2; a <= q; ++a) T[d][a] = 2 * s * T[d][a - 1] - T[d][a - 2];
    }
    for (int a = 0, m = 0; a <= q; ++a)
      for (int b = 0; a + b <= q; ++b)
        for (int c = 0; a + b + c <= q; ++c, ++m) {
          const double t = T[0][a] * T[1][b] * T[2][c];
          mx[m] += t * sfx[k];
          my[m] += t * sfy[k];
          mz[m] += t * sfz[k];
        }
  }
}

// Compiled for AVX-512, AVX2 + FMA and baseline x86-64, picked at run time (as the single layer's
// sums): the lane loops below are one vector operation each.
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__) && !defined(__SANITIZE_ADDRESS__)
__attribute__((target_clones("arch=x86-64-v4", "arch=x86-64-v3", "default")))
#endif
void chebyshev_moments(const double* S, const double* centre, int q, const double* sx, const double* sy,
                       const double* sz, const double* sfx, const double* sfy, const double* sfz, int count,
                       double* mx, double* my, double* mz) {
  constexpr int L = 4;  // points per block: one AVX2 register of doubles
  const int nm = chebyshev_moment_count(q);
  alignas(64) double acc[3][chebyshev_moment_count(8)][L] = {};
  alignas(64) double T[3][9][L], g[3][L], tab[L], t[L];
  for (int k0 = 0; k0 < count; k0 += L) {
    const int n = std::min(L, count - k0);
    for (int l = 0; l < L; ++l) {
      // Lanes past the end: a point at the centre with zero weight adds nothing.
      const int k = k0 + std::min(l, n - 1);
      const double r[3] = {sx[k] - centre[0], sy[k] - centre[1], sz[k] - centre[2]};
      const bool live = l < n;
      for (int d = 0; d < 3; ++d) T[d][1][l] = S[d] * r[0] + S[3 + d] * r[1] + S[6 + d] * r[2];
      g[0][l] = live ? sfx[k] : 0.0;
      g[1][l] = live ? sfy[k] : 0.0;
      g[2][l] = live ? sfz[k] : 0.0;
    }
    for (int d = 0; d < 3; ++d) {
#pragma omp simd
      for (int l = 0; l < L; ++l) T[d][0][l] = 1;
      for (int a = 2; a <= q; ++a) {
#pragma omp simd
        for (int l = 0; l < L; ++l) T[d][a][l] = 2 * T[d][1][l] * T[d][a - 1][l] - T[d][a - 2][l];
      }
    }
    for (int a = 0, m = 0; a <= q; ++a)
      for (int b = 0; a + b <= q; ++b) {
#pragma omp simd
        for (int l = 0; l < L; ++l) tab[l] = T[0][a][l] * T[1][b][l];
        for (int c = 0; a + b + c <= q; ++c, ++m) {
#pragma omp simd
          for (int l = 0; l < L; ++l) {
            t[l] = tab[l] * T[2][c][l];
            acc[0][m][l] += t[l] * g[0][l];
            acc[1][m][l] += t[l] * g[1][l];
            acc[2][m][l] += t[l] * g[2][l];
          }
        }
      }
  }
  for (int m = 0; m < nm; ++m) {
    mx[m] += (acc[0][m][0] + acc[0][m][1]) + (acc[0][m][2] + acc[0][m][3]);
    my[m] += (acc[1][m][0] + acc[1][m][1]) + (acc[1][m][2] + acc[1][m][3]);
    mz[m] += (acc[2][m][0] + acc[2][m][1]) + (acc[2][m][2] + acc[2][m][3]);
  }
}

}  // namespace bendlab
