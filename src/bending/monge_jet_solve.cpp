#include "bendlab/bending/monge_jet_solve.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>

#include "bendlab/core/types.hpp"

namespace bendlab {

void JetLaneSamples::reset(int n) {
  count = n;
  const auto size = static_cast<std::size_t>(n) * kJetLanes;
  xi.assign(size, 0.0);
  eta.assign(size, 0.0);
  height.assign(size, 0.0);
  weight.assign(size, 0.0);
}

namespace {

constexpr int L = kJetLanes;

constexpr int unknowns_of(int degree) { return (degree + 1) * (degree + 2) / 2 - 1; }

/// Exponents (a, b) of basis function k: by total degree, then by b (monomial_index's order).
template <int D>
struct Basis {
  int a[unknowns_of(D)], b[unknowns_of(D)];
  constexpr Basis() : a{}, b{} {
    int k = 0;
    for (int t = 1; t <= D; ++t)
      for (int q = 0; q <= t; ++q, ++k) a[k] = t - q, b[k] = q;
  }
};

constexpr int monomial_index(int a, int b) { return (a + b - 1) * (a + b + 2) / 2 + b; }

template <int D>
__attribute__((always_inline)) inline void solve_body(const double* xi, const double* eta, const double* h,
                                                      const double* w, int m, double* coef, bool* determined,
                                                      const double* inv_scale, double* laplacian_y) {
  constexpr int P = unknowns_of(D), Q = 2 * D + 1;
  constexpr Basis<D> basis;
  alignas(64) double mu[Q][Q][L] = {};  // mu[p][q] = sum w xi^p eta^q, p + q <= 2D
  alignas(64) double rhs[P][L] = {};
  for (int j = 0; j < m; ++j) {
    const double* xj = xi + j * L;
    const double* ej = eta + j * L;
    const double* hj = h + j * L;
    const double* wj = w + j * L;
    alignas(64) double pu[Q][L], pv[Q][L];
    for (int l = 0; l < L; ++l) pu[0][l] = wj[l], pv[0][l] = 1.0;
    for (int k = 1; k < Q; ++k)
      for (int l = 0; l < L; ++l) pu[k][l] = pu[k - 1][l] * xj[l], pv[k][l] = pv[k - 1][l] * ej[l];
    // Unrolled, so that every index is a constant and every sum a register-held FMA.
    for (int p = 0; p < Q; ++p)
      for (int q = 0; q < Q - p; ++q)
        for (int l = 0; l < L; ++l) mu[p][q][l] += pu[p][l] * pv[q][l];
    for (int k = 0; k < P; ++k)
      for (int l = 0; l < L; ++l) rhs[k][l] += hj[l] * pu[basis.a[k]][l] * pv[basis.b[k]][l];
  }
  // The normal matrix's lower triangle from the moments, by columns: column c holds rows c .. P-1
  // contiguously from col[c], so that every loop below walks memory with a fixed stride.
  constexpr auto col = [] {
    std::array<int, P + 1> start{};
    for (int c = 0; c < P; ++c) start[c + 1] = start[c] + (P - c);
    return start;
  }();
  alignas(64) double a[P * (P + 1) / 2][L];
  alignas(64) double max_diag[L] = {};
  for (int c = 0; c < P; ++c)
    for (int r = c; r < P; ++r)
      for (int l = 0; l < L; ++l) a[col[c] + r - c][l] = mu[basis.a[r] + basis.a[c]][basis.b[r] + basis.b[c]][l];
  for (int c = 0; c < P; ++c)
    for (int l = 0; l < L; ++l) max_diag[l] = std::max(max_diag[l], a[col[c]][l]);
  // Cholesky, right-looking (L L^T = M in place): column k is scaled, then the trailing matrix is
  // updated. The updates of a step are independent of each other, so the FMAs pipeline (a
  // dot-product form chains each entry's FMAs and runs at their latency). A pivot that is not
  // positive is replaced by 1 so that the lane runs on with finite numbers, and the lane is flagged.
  alignas(64) double inv_diag[P][L];
  alignas(64) double min_pivot[L];
  for (int l = 0; l < L; ++l) min_pivot[l] = HUGE_VAL;
  for (int k = 0; k < P; ++k) {
    double(*ck)[L] = a + col[k];  // ck[r - k] = M_rk, r >= k
    for (int l = 0; l < L; ++l) {
      const bool positive = ck[0][l] > 0;  // false for NaN too
      min_pivot[l] = positive ? std::min(min_pivot[l], ck[0][l]) : -1.0;
      const double d = std::sqrt(positive ? ck[0][l] : 1.0);
      ck[0][l] = d;
      inv_diag[k][l] = 1.0 / d;
    }
    for (int i = 1; i < P - k; ++i)
      for (int l = 0; l < L; ++l) ck[i][l] *= inv_diag[k][l];
    for (int c = k + 1; c < P; ++c) {
      alignas(64) double lck[L];
      for (int l = 0; l < L; ++l) lck[l] = ck[c - k][l];
      double(*cc)[L] = a + col[c];
      for (int i = 0; i < P - c; ++i)  // row r = c + i
        for (int l = 0; l < L; ++l) cc[i][l] -= ck[c - k + i][l] * lck[l];
    }
  }
  // M x = b with the factor: L y = b by columns (b overwritten by y); then L^T x = y by dot
  // products down each column (two partial sums).
  const auto solve = [&](double(*b)[L], double* x) __attribute__((always_inline)) {
    for (int k = 0; k < P; ++k) {
      alignas(64) double yk[L];
      for (int l = 0; l < L; ++l) yk[l] = b[k][l] *= inv_diag[k][l];
      const double(*ck)[L] = a + col[k];
      for (int i = 1; i < P - k; ++i)
        for (int l = 0; l < L; ++l) b[k + i][l] -= ck[i][l] * yk[l];
    }
    for (int r = P - 1; r >= 0; --r) {
      const double(*cr)[L] = a + col[r];  // cr[i] = L_(r+i) r
      alignas(64) double s0[L], s1[L];
      for (int l = 0; l < L; ++l) s0[l] = b[r][l], s1[l] = 0.0;
      int i = 1;
      for (; i + 1 < P - r; i += 2)
        for (int l = 0; l < L; ++l) {
          s0[l] -= cr[i][l] * x[(r + i) * L + l];
          s1[l] -= cr[i + 1][l] * x[(r + i + 1) * L + l];
        }
      for (; i < P - r; ++i)
        for (int l = 0; l < L; ++l) s0[l] -= cr[i][l] * x[(r + i) * L + l];
      for (int l = 0; l < L; ++l) x[r * L + l] = (s0[l] + s1[l]) * inv_diag[r][l];
    }
  };
  solve(rhs, coef);
  for (int l = 0; l < L; ++l) determined[l] = min_pivot[l] > kJetMinPivotRatio * max_diag[l];
  if (laplacian_y == nullptr) return;
  // The Laplace-Beltrami operator of the fitted graph at the node applied to a field's jet of the
  // same basis, l . c (monge_jet_laplacian's derivation): Lap_S f = g^ab f_ab - T (grad h . grad f)
  // / W^2, T = g^ab h_ab, g^-1 = I - grad h grad h^T / W^2, W^2 = 1 + |grad h|^2, with the height's
  // derivatives h_u = c_10 / s, h_uu = 2 c_20 / s^2, h_uv = c_11 / s^2 from this lane's fit. Then
  // y = M^-1 l, so that the weight of sample j is w_j phi_j . y.
  alignas(64) double lv[P][L] = {};
  for (int l = 0; l < L; ++l) {
    const double is = inv_scale[l], is2 = is * is;
    const double hu = coef[monomial_index(1, 0) * L + l] * is, hv = coef[monomial_index(0, 1) * L + l] * is;
    const double huu = 2 * coef[monomial_index(2, 0) * L + l] * is2, huv = coef[monomial_index(1, 1) * L + l] * is2,
                 hvv = 2 * coef[monomial_index(0, 2) * L + l] * is2;
    const double w2 = 1 + hu * hu + hv * hv;
    const double g11 = 1 - hu * hu / w2, g12 = -hu * hv / w2, g22 = 1 - hv * hv / w2;
    const double tr = g11 * huu + 2 * g12 * huv + g22 * hvv;
    lv[monomial_index(1, 0)][l] = -tr * hu / w2 * is;
    lv[monomial_index(0, 1)][l] = -tr * hv / w2 * is;
    lv[monomial_index(2, 0)][l] = 2 * g11 * is2;
    lv[monomial_index(1, 1)][l] = 2 * g12 * is2;
    lv[monomial_index(0, 2)][l] = 2 * g22 * is2;
  }
  solve(lv, laplacian_y);
}

// Compiled for AVX-512, AVX2+FMA and baseline x86-64 and picked at run time (as belkin_kernel.cpp's and
// the boundary integral's kernels).
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__) && !defined(__SANITIZE_ADDRESS__)
#define BENDLAB_JET_CLONES __attribute__((target_clones("arch=x86-64-v4", "arch=x86-64-v3", "default")))
#else
#define BENDLAB_JET_CLONES
#endif
#define BENDLAB_JET_KERNEL(D)                                                                              \
  BENDLAB_JET_CLONES void solve_lanes##D(const double* xi, const double* eta, const double* h, const double* w, \
                                         int m, double* coef, bool* determined, const double* inv_scale,   \
                                         double* laplacian_y) {                                            \
    solve_body<D>(xi, eta, h, w, m, coef, determined, inv_scale, laplacian_y);                            \
  }
BENDLAB_JET_KERNEL(4)
BENDLAB_JET_KERNEL(5)
BENDLAB_JET_KERNEL(6)
#undef BENDLAB_JET_KERNEL

}  // namespace

void solve_jet_lanes(int degree, const JetLaneSamples& s, double* coefficients, bool* determined,
                     const double* inv_scale, double* laplacian_y) {
  if ((inv_scale == nullptr) != (laplacian_y == nullptr))
    throw Error("solve_jet_lanes: the Laplacian needs both the inverse scales and room for y");
  const auto size = static_cast<std::size_t>(s.count) * L;
  if (s.count < 0 || s.xi.size() != size || s.eta.size() != size || s.height.size() != size ||
      s.weight.size() != size)
    throw Error("solve_jet_lanes: the sample arrays do not hold count * kJetLanes values");
  const double* x = s.xi.data();
  const double* e = s.eta.data();
  const double* h = s.height.data();
  const double* w = s.weight.data();
  switch (degree) {
    case 4: return solve_lanes4(x, e, h, w, s.count, coefficients, determined, inv_scale, laplacian_y);
    case 5: return solve_lanes5(x, e, h, w, s.count, coefficients, determined, inv_scale, laplacian_y);
    case 6: return solve_lanes6(x, e, h, w, s.count, coefficients, determined, inv_scale, laplacian_y);
    default: throw Error(fmt::format("method M: degree must be 4, 5 or 6, got {}", degree));
  }
}

}  // namespace bendlab
