#include "bendlab/flow/lbm/lattice.hpp"

#include <fmt/format.h>
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <utility>

namespace bendlab::lbm {

namespace {

// Everything inside the row loop must be inlined for it to vectorise.
#if defined(__GNUC__)
#define LBM_INLINE [[gnu::always_inline]] inline
#else
#define LBM_INLINE inline
#endif

// The collisions are written as straight-line code over the 19 directions (index_sequence), with
// the velocity components folded in at compile time, so that the loop over a row vectorises
// across nodes: no multiplication by a zero velocity component remains (the compiler may not drop
// 0 * x or x + 0 under IEEE semantics).
template <int C>
LBM_INLINE double term(double v) {
  if constexpr (C == 1) {
    return v;
  } else if constexpr (C == -1) {
    return -v;
  } else {
    return 0.0;
  }
}
// c . (a, b, c) for a D3Q19 velocity (at most two non-zero components).
template <int X, int Y, int Z>
LBM_INLINE double cdot(double a, double b, double c) {
  if constexpr (X != 0 && Y != 0) {
    return term<X>(a) + term<Y>(b);
  } else if constexpr (X != 0 && Z != 0) {
    return term<X>(a) + term<Z>(c);
  } else if constexpr (Y != 0 && Z != 0) {
    return term<Y>(b) + term<Z>(c);
  } else if constexpr (X != 0) {
    return term<X>(a);
  } else if constexpr (Y != 0) {
    return term<Y>(b);
  } else if constexpr (Z != 0) {
    return term<Z>(c);
  } else {
    return 0.0;
  }
}
using Directions = std::make_index_sequence<kQ>;
using Pairs = std::make_index_sequence<(kQ - 1) / 2>;  // pair k: directions 2k + 1 and 2k + 2 = opposite

// The moments from the sums s_k = f_c + f_-c and differences d_k = f_c - f_-c of the 9 pairs of
// opposite directions (c the odd one of the pair): rho = f_0 + sum s, j = sum c d,
// Pi = sum c c s. Half the additions of summing the 19 directions moment by moment.
struct PairSums {
  double s[(kQ - 1) / 2], d[(kQ - 1) / 2];
};
template <std::size_t... K>
LBM_INLINE PairSums pair_sums(const double* f, std::index_sequence<K...>) {
  PairSums p;
  ((p.s[K] = f[2 * K + 1] + f[2 * K + 2], p.d[K] = f[2 * K + 1] - f[2 * K + 2]), ...);
  return p;
}
// sum_k c_a(k) v_k.
template <const std::array<int, kQ>& C, std::size_t... K>
LBM_INLINE double pair_moment(const double* v, std::index_sequence<K...>) {
  double r = 0.0;
  ((C[2 * K + 1] == 1 ? (r += v[K]) : (C[2 * K + 1] == -1 ? (r -= v[K]) : r)), ...);
  return r;
}
// sum_k c_a(k) c_b(k) v_k for a != b, and sum_k c_a(k)^2 v_k.
template <const std::array<int, kQ>& A, const std::array<int, kQ>& B, std::size_t... K>
LBM_INLINE double pair_cross(const double* v, std::index_sequence<K...>) {
  double r = 0.0;
  ((A[2 * K + 1] * B[2 * K + 1] == 1 ? (r += v[K]) : (A[2 * K + 1] * B[2 * K + 1] == -1 ? (r -= v[K]) : r)), ...);
  return r;
}
template <const std::array<int, kQ>& A, std::size_t... K>
LBM_INLINE double pair_square(const double* v, std::index_sequence<K...>) {
  double r = 0.0;
  ((A[2 * K + 1] != 0 ? (r += v[K]) : r), ...);
  return r;
}
template <std::size_t... K>
LBM_INLINE double pair_total(const double* v, std::index_sequence<K...>) {
  return (v[K] + ...);
}

// BGK + Guo (technical note section 1), omega = 1/tau, a = 1 - 1/(2 tau):
//   f_i* = (1 - omega) f_i + omega f_i^eq + a w_i [3 (c_i - u).F + 9 (c_i.u)(c_i.F)],
// evaluated per pair of opposite directions (c, -c): with A = c.u and B = c.F the added term is
// w (even + odd) for c and w (even - odd) for -c, even = omega rho (1 - 1.5 u.u) - 3 a u.F
// + 4.5 omega rho A^2 + 9 a A B and odd = 3 omega rho A + 3 a B, so each pair costs one
// evaluation. kTauOne drops the (1 - omega) f_i term (omega = 1: the populations enter only
// through their moments).
template <bool kTauOne>
struct Bgk {
  double omega, a;
  template <std::size_t K>
  LBM_INLINE void relax_pair(double* f, double keep, double e0, double e2, double e4, double o1, double o3,
                             double ux, double uy, double uz, double Fx, double Fy, double Fz) const {
    constexpr int q = 2 * static_cast<int>(K) + 1, qb = q + 1;  // the pair (2k - 1, 2k), k = K + 1
    static_assert(opposite(q) == qb);
    constexpr int X = kCx[q], Y = kCy[q], Z = kCz[q];
    const double A = cdot<X, Y, Z>(ux, uy, uz);
    const double B = cdot<X, Y, Z>(Fx, Fy, Fz);
    const double even = kW[q] * (e0 + A * (e2 * A + e4 * B));
    const double odd = kW[q] * (o1 * A + o3 * B);
    if constexpr (kTauOne) {
      f[q] = even + odd;
      f[qb] = even - odd;
    } else {
      f[q] = keep * f[q] + (even + odd);
      f[qb] = keep * f[qb] + (even - odd);
    }
  }
  template <std::size_t... K>
  LBM_INLINE void apply(double* f, double Fx, double Fy, double Fz, std::index_sequence<K...>) const {
    const Pairs k;
    const PairSums p = pair_sums(f, k);
    const double rho = f[0] + pair_total(p.s, k);
    const double jx = pair_moment<kCx>(p.d, k), jy = pair_moment<kCy>(p.d, k), jz = pair_moment<kCz>(p.d, k);
    const double ir = 1.0 / rho;
    const double ux = (jx + 0.5 * Fx) * ir, uy = (jy + 0.5 * Fy) * ir, uz = (jz + 0.5 * Fz) * ir;
    const double uu = ux * ux + uy * uy + uz * uz, uF = ux * Fx + uy * Fy + uz * Fz;
    const double orho = omega * rho;
    const double e0 = orho * (1.0 - 1.5 * uu) - 3.0 * a * uF, e2 = 4.5 * orho, e4 = 9.0 * a;
    const double o1 = 3.0 * orho, o3 = 3.0 * a, keep = 1.0 - omega;
    if constexpr (kTauOne) {
      f[0] = kW[0] * e0;
    } else {
      f[0] = keep * f[0] + kW[0] * e0;
    }
    (relax_pair<K>(f, keep, e0, e2, e4, o1, o3, ux, uy, uz, Fx, Fy, Fz), ...);
  }
  LBM_INLINE void operator()(double* f, double Fx, double Fy, double Fz) const {
    apply(f, Fx, Fy, Fz, Pairs{});
  }
};

// ESPResSo's MRT with default bulk and ghost relaxation as a regularised scheme (section 1):
// gs = 1 - 1/tau relaxes the traceless non-equilibrium stress, the trace is dropped, as = 1 - 1/(2 tau).
// Rebuilt per pair of opposite directions: f_+-c = w (even +- odd) with even = rho + 4.5 (c.S.c - tr S / 3)
// and odd = 3 c.j*, the weights folded into the terms beforehand (Rebuild), so that a pair costs
// a few additions: for c = e_a, w1 even = b1 + 4.5 w1 S_aa and w1 odd = 6 w2 j*_a (w1 = 2 w2); for
// c = e_a +- e_b, w2 even = (b2 + 4.5 w2 (S_aa + S_bb)) +- 9 w2 S_ab and w2 odd = 3 w2 (j*_a +- j*_b),
// with b = w (rho - 4.5 tr S / 3).
struct Regularized {
  double gs, as;
  struct Rebuild {
    double b1, t1[3];  // w1 (rho - 4.5 trs), 4.5 w1 S_aa
    double e2[3];      // b2 + 4.5 w2 (S_aa + S_bb) for the planes xy, xz, yz
    double t2[3];      // 9 w2 S_ab for xy, xz, yz
    double j2[3];      // 3 w2 j*_a
  };
  template <std::size_t K>
  LBM_INLINE static void rebuild_pair(double* f, const Rebuild& r) {
    constexpr int q = 2 * static_cast<int>(K) + 1, qb = q + 1;
    static_assert(opposite(q) == qb);
    constexpr int c[3] = {kCx[q], kCy[q], kCz[q]};
    constexpr int n = (c[0] != 0) + (c[1] != 0) + (c[2] != 0);
    double even, odd;
    if constexpr (n == 1) {
      constexpr int a = c[0] != 0 ? 0 : (c[1] != 0 ? 1 : 2);
      static_assert(c[a] == 1);
      even = r.b1 + r.t1[a];
      odd = 2.0 * r.j2[a];
    } else {
      constexpr int a = c[0] != 0 ? 0 : 1, b = c[2] != 0 ? 2 : 1;
      constexpr int plane = a == 0 ? (b == 1 ? 0 : 1) : 2;
      static_assert(c[a] == 1 && a < b);
      if constexpr (c[b] == 1) {
        even = r.e2[plane] + r.t2[plane];
        odd = r.j2[a] + r.j2[b];
      } else {
        even = r.e2[plane] - r.t2[plane];
        odd = r.j2[a] - r.j2[b];
      }
    }
    f[q] = even + odd;
    f[qb] = even - odd;
  }
  template <std::size_t... K>
  LBM_INLINE void apply(double* f, double Fx, double Fy, double Fz, std::index_sequence<K...> k) const {
    const PairSums p = pair_sums(f, k);
    const double rho = f[0] + pair_total(p.s, k);
    const double jx = pair_moment<kCx>(p.d, k), jy = pair_moment<kCy>(p.d, k), jz = pair_moment<kCz>(p.d, k);
    const double pxx = pair_square<kCx>(p.s, k), pyy = pair_square<kCy>(p.s, k), pzz = pair_square<kCz>(p.s, k);
    const double pxy = pair_cross<kCx, kCy>(p.s, k), pxz = pair_cross<kCx, kCz>(p.s, k), pyz = pair_cross<kCy, kCz>(p.s, k);
    const double ir = 1.0 / rho;
    const double ux = (jx + 0.5 * Fx) * ir, uy = (jy + 0.5 * Fy) * ir, uz = (jz + 0.5 * Fz) * ir;
    const double r3 = rho / 3.0;
    const double nxx = pxx - r3 - rho * ux * ux, nyy = pyy - r3 - rho * uy * uy, nzz = pzz - r3 - rho * uz * uz;
    const double nxy = pxy - rho * ux * uy, nxz = pxz - rho * ux * uz, nyz = pyz - rho * uy * uz;
    const double tr = (nxx + nyy + nzz) / 3.0;
    const double uF = ux * Fx + uy * Fy + uz * Fz;
    const double iso = uF / 3.0 - as * (2.0 / 3.0) * uF;
    // S = Pi* - rho/3 I.
    const double sxx = rho * ux * ux + gs * (nxx - tr) + 2.0 * as * ux * Fx + iso;
    const double syy = rho * uy * uy + gs * (nyy - tr) + 2.0 * as * uy * Fy + iso;
    const double szz = rho * uz * uz + gs * (nzz - tr) + 2.0 * as * uz * Fz + iso;
    const double sxy = rho * ux * uy + gs * nxy + as * (ux * Fy + uy * Fx);
    const double sxz = rho * ux * uz + gs * nxz + as * (ux * Fz + uz * Fx);
    const double syz = rho * uy * uz + gs * nyz + as * (uy * Fz + uz * Fy);
    const double trs = (sxx + syy + szz) / 3.0;
    constexpr double w1 = kW1, w2 = kW2;
    const double base = rho - 4.5 * trs;
    f[0] = kW0 * base;
    Rebuild r;
    r.b1 = w1 * base;
    r.t1[0] = 4.5 * w1 * sxx, r.t1[1] = 4.5 * w1 * syy, r.t1[2] = 4.5 * w1 * szz;
    const double b2 = w2 * base, hxx = 4.5 * w2 * sxx, hyy = 4.5 * w2 * syy, hzz = 4.5 * w2 * szz;
    r.e2[0] = b2 + (hxx + hyy), r.e2[1] = b2 + (hxx + hzz), r.e2[2] = b2 + (hyy + hzz);
    r.t2[0] = 9.0 * w2 * sxy, r.t2[1] = 9.0 * w2 * sxz, r.t2[2] = 9.0 * w2 * syz;
    r.j2[0] = 3.0 * w2 * (jx + Fx), r.j2[1] = 3.0 * w2 * (jy + Fy), r.j2[2] = 3.0 * w2 * (jz + Fz);
    (rebuild_pair<K>(f, r), ...);
  }
  LBM_INLINE void operator()(double* f, double Fx, double Fy, double Fz) const { apply(f, Fx, Fy, Fz, Pairs{}); }
};

// TRT + Guo (Ginzburg's two relaxation times): per pair of opposite directions (c, -c) the even
// part f+ = (f_c + f_-c)/2 relaxes with omega+ = 1/tau and the odd part f- = (f_c - f_-c)/2 with
// omega-; the Guo source w [3 (c - u).F + 9 (c.u)(c.F)] splits into its even part
// w (-3 u.F + 9 A B) and odd part 3 w B (A = c.u, B = c.F), weighted by 1 - omega+/2 and
// 1 - omega-/2:
//   f_+-c* = [(1 - omega+) f+ + even] +- [(1 - omega-) f- + odd],
//   even = w (omega+ rho (1 - 1.5 u.u + 4.5 A^2) + a+ (-3 u.F + 9 A B)), odd = w (3 omega- rho A + 3 a- B).
struct Trt {
  double op, om;  // omega+, omega-
  template <std::size_t K>
  LBM_INLINE void relax_pair(double* f, const double* s, const double* d, double e0, double e2, double e4,
                             double o1, double o3, double ux, double uy, double uz, double Fx, double Fy, double Fz) const {
    constexpr int q = 2 * static_cast<int>(K) + 1, qb = q + 1;
    static_assert(opposite(q) == qb);
    constexpr int X = kCx[q], Y = kCy[q], Z = kCz[q];
    const double A = cdot<X, Y, Z>(ux, uy, uz);
    const double B = cdot<X, Y, Z>(Fx, Fy, Fz);
    const double even = 0.5 * (1.0 - op) * s[K] + kW[q] * (e0 + A * (e2 * A + e4 * B));
    const double odd = 0.5 * (1.0 - om) * d[K] + kW[q] * (o1 * A + o3 * B);
    f[q] = even + odd;
    f[qb] = even - odd;
  }
  template <std::size_t... K>
  LBM_INLINE void apply(double* f, double Fx, double Fy, double Fz, std::index_sequence<K...>) const {
    const Pairs k;
    const PairSums p = pair_sums(f, k);
    const double rho = f[0] + pair_total(p.s, k);
    const double jx = pair_moment<kCx>(p.d, k), jy = pair_moment<kCy>(p.d, k), jz = pair_moment<kCz>(p.d, k);
    const double ir = 1.0 / rho;
    const double ux = (jx + 0.5 * Fx) * ir, uy = (jy + 0.5 * Fy) * ir, uz = (jz + 0.5 * Fz) * ir;
    const double uu = ux * ux + uy * uy + uz * uz, uF = ux * Fx + uy * Fy + uz * Fz;
    const double ap = 1.0 - 0.5 * op, am = 1.0 - 0.5 * om;
    const double orho = op * rho;
    const double e0 = orho * (1.0 - 1.5 * uu) - 3.0 * ap * uF, e2 = 4.5 * orho, e4 = 9.0 * ap;
    const double o1 = 3.0 * om * rho, o3 = 3.0 * am;
    f[0] = (1.0 - op) * f[0] + kW[0] * e0;
    (relax_pair<K>(f, p.s, p.d, e0, e2, e4, o1, o3, ux, uy, uz, Fx, Fy, Fz), ...);
  }
  LBM_INLINE void operator()(double* f, double Fx, double Fy, double Fz) const { apply(f, Fx, Fy, Fz, Pairs{}); }
};

// A step of this many nodes takes some 50 us on one core, ten times what opening a parallel region
// costs; smaller lattices (tests) step on one thread. (The 10 um tube, 23040 nodes, was serial at
// the former 2^15.)
constexpr std::size_t kParallelNodes = std::size_t{1} << 12;

struct StepArgs {
  double* f;
  std::size_t stride;  // doubles between two slots (Lattice::slot_stride)
  int nx, ny, nz;
  int j0, nj;  // the layers stepped: j0 <= j < j0 + nj (all of them: 0, ny)
  bool walls, odd;
  double v;
  const double* F[3];
  const std::uint8_t* solid;  // per row j + ny k, or null (no cross-section)
  double g[3];                // the uniform body force
};

// Where each of the 19 populations of a run of nodes x0..x1-1 in one row is read from and written
// to: slot base + offset + x, plus a constant (the wall term of the bounce-back).
struct RowPlan {
  const double* rbase[kQ];
  double* wbase[kQ];
  std::ptrdiff_t roff[kQ], woff[kQ];
  double radd[kQ], wadd[kQ];
  std::uint32_t rwall = 0, wwall = 0;  // bit q: population q is read from (written to) a wall
};

// i modulo n for -n <= i < 2n (every use is a node index plus or minus one): no division, which
// in the per-row plans and per-node gathers cost a fifth of a capsule run's time.
LBM_INLINE int wrap(int i, int n) { return i < 0 ? i + n : (i >= n ? i - n : i); }

template <bool kAdd, class Coll, std::size_t... Q>
LBM_INLINE void row_kernel_impl(const RowPlan& p, const double* __restrict Fx, const double* __restrict Fy,
                            const double* __restrict Fz, const double* g, int x0, int x1, const Coll& coll,
                            std::index_sequence<Q...>) {
  const double gx = g[0], gy = g[1], gz = g[2];
  const double* r[kQ] = {(p.rbase[Q] + (p.roff[Q] + x0))...};
  double* w[kQ] = {(p.wbase[Q] + (p.woff[Q] + x0))...};
  const double* fx = Fx + x0;
  const double* fy = Fy + x0;
  const double* fz = Fz + x0;
  const int n = x1 - x0;
  // Each node reads and writes its own 19 locations (AA pattern): the iterations are independent.
#pragma GCC ivdep
  for (int x = 0; x < n; ++x) {
    double f[kQ];
    if constexpr (kAdd) {
      ((f[Q] = r[Q][x] + p.radd[Q]), ...);
    } else {
      ((f[Q] = r[Q][x]), ...);
    }
    coll(f, fx[x] + gx, fy[x] + gy, fz[x] + gz);
    if constexpr (kAdd) {
      ((w[Q][x] = f[Q] + p.wadd[Q]), ...);
    } else {
      ((w[Q][x] = f[Q]), ...);
    }
  }
}

template <bool kAdd, class Coll>
LBM_INLINE void row_kernel(const RowPlan& p, const double* Fx, const double* Fy, const double* Fz, const double* g,
                           int x0, int x1, const Coll& coll) {
  row_kernel_impl<kAdd>(p, Fx, Fy, Fz, g, x0, x1, coll, Directions{});
}

// The odd (streaming) step's plan for row (j, k): the offsets of the interior nodes (x - c_x
// stays in the row; row_end_plan derives the two ends). Returns whether any link of the row meets
// a moving flat wall (whose bounce-back adds a constant); a resting cross-section wall adds nothing.
bool odd_plan(const StepArgs& a, int j, int k, RowPlan& p) {
  const std::size_t n = a.stride;
  p.rwall = p.wwall = 0;
  const std::ptrdiff_t row = static_cast<std::ptrdiff_t>(a.nx) * (j + static_cast<std::ptrdiff_t>(a.ny) * k);
  bool wall = false;
  for (int q = 0; q < kQ; ++q) {
    const int qb = opposite(q);
    // Read population q from x - c_q (slot qbar), or bounce it back from the wall.
    int ks = k - kCz[q];
    if (a.walls && (ks < 0 || ks >= a.nz)) {
      const double uw = ks < 0 ? -a.v : a.v;
      p.rbase[q] = a.f + q * n;
      p.roff[q] = row;
      p.radd[q] = 6.0 * kW[q] * kCx[q] * uw;
      p.rwall |= 1u << q;
      wall = true;
    } else {
      ks = wrap(ks, a.nz);
      const int js = wrap(j - kCy[q], a.ny);
      const std::ptrdiff_t srow = static_cast<std::ptrdiff_t>(a.nx) * (js + static_cast<std::ptrdiff_t>(a.ny) * ks);
      if (a.solid && a.solid[js + static_cast<std::ptrdiff_t>(a.ny) * ks]) {
        // A resting wall of the cross-section: plain bounce-back here, moved to the wall's true
        // position after the step (Lattice::apply_interpolated_bounce_back).
        p.rbase[q] = a.f + q * n;
        p.roff[q] = row;
        p.radd[q] = 0.0;
        p.rwall |= 1u << q;
      } else {
        p.rbase[q] = a.f + qb * n;
        p.roff[q] = srow - kCx[q];
        p.radd[q] = 0.0;
      }
    }
    // Write post-collision population q to x + c_q (slot q), or reflect it at the wall into
    // slot qbar of this node, where the next (even) step reads population qbar.
    int kd = k + kCz[q];
    if (a.walls && (kd < 0 || kd >= a.nz)) {
      const double uw = kd < 0 ? -a.v : a.v;
      p.wbase[q] = a.f + qb * n;
      p.woff[q] = row;
      p.wadd[q] = -6.0 * kW[q] * kCx[q] * uw;
      p.wwall |= 1u << q;
      wall = true;
    } else {
      kd = wrap(kd, a.nz);
      const int jd = wrap(j + kCy[q], a.ny);
      const std::ptrdiff_t drow = static_cast<std::ptrdiff_t>(a.nx) * (jd + static_cast<std::ptrdiff_t>(a.ny) * kd);
      if (a.solid && a.solid[jd + static_cast<std::ptrdiff_t>(a.ny) * kd]) {
        p.wbase[q] = a.f + qb * n;
        p.woff[q] = row;
        p.wadd[q] = 0.0;
        p.wwall |= 1u << q;
      } else {
        p.wbase[q] = a.f + q * n;
        p.woff[q] = drow + kCx[q];
        p.wadd[q] = 0.0;
      }
    }
  }
  return wall;
}

// The plan of the single node x = xe from the interior plan of its row (odd_plan):
// only the x offsets of the links with c_x != 0 that do not meet a wall change (periodic wrap in
// x), so the row ends cost a copy, not two more plans.
LBM_INLINE void row_end_plan(const RowPlan& interior, int nx, int xe, RowPlan& p) {
  p = interior;
  for (int q = 0; q < kQ; ++q) {
    const int cx = kCx[q];
    if (cx == 0) continue;
    if (!(interior.rwall >> q & 1u)) p.roff[q] += cx + wrap(xe - cx, nx) - xe;
    if (!(interior.wwall >> q & 1u)) p.woff[q] += wrap(xe + cx, nx) - xe - cx;
  }
}

template <class Coll>
LBM_INLINE void process_rows_impl(const StepArgs& a, int row0, int row1, const Coll& coll) {
  RowPlan p, end;
  for (int t = row0; t < row1; ++t) {
    const int j = a.j0 + t % a.nj, k = t / a.nj;
    const int r = j + a.ny * k;
    const std::ptrdiff_t row = static_cast<std::ptrdiff_t>(a.nx) * r;
    const double* Fx = a.F[0] + row;
    const double* Fy = a.F[1] + row;
    const double* Fz = a.F[2] + row;
    if (a.solid && a.solid[r]) continue;
    if (!a.odd) {
      for (int q = 0; q < kQ; ++q) {
        p.rbase[q] = a.f + q * a.stride;
        p.wbase[q] = a.f + opposite(q) * a.stride;
        p.roff[q] = p.woff[q] = row;
      }
      row_kernel<false>(p, Fx, Fy, Fz, a.g, 0, a.nx, coll);
      continue;
    }
    const bool wall = odd_plan(a, j, k, p);
    if (a.nx > 2) {
      if (wall) {
        row_kernel<true>(p, Fx, Fy, Fz, a.g, 1, a.nx - 1, coll);
      } else {
        row_kernel<false>(p, Fx, Fy, Fz, a.g, 1, a.nx - 1, coll);
      }
    }
    // The row ends, where x -+ c_x wraps: x = 0 and (if it is another node) x = nx - 1.
    for (int e = 0; e < (a.nx > 1 ? 2 : 1); ++e) {
      const int xe = e == 0 ? 0 : a.nx - 1;
      row_end_plan(p, a.nx, xe, end);
      if (wall) {
        row_kernel<true>(end, Fx, Fy, Fz, a.g, xe, xe + 1, coll);
      } else {
        row_kernel<false>(end, Fx, Fy, Fz, a.g, xe, xe + 1, coll);
      }
    }
  }
}

// The row loops, compiled for AVX-512, AVX2 and the baseline and chosen when the program starts.
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__)
#define BENDLAB_LBM_CLONES __attribute__((target_clones("arch=x86-64-v4", "arch=x86-64-v3", "default")))
#else
#define BENDLAB_LBM_CLONES
#endif

BENDLAB_LBM_CLONES void process_rows_bgk(const StepArgs& a, int row0, int row1, const Bgk<false>& c) {
  process_rows_impl(a, row0, row1, c);
}
BENDLAB_LBM_CLONES void process_rows_bgk1(const StepArgs& a, int row0, int row1, const Bgk<true>& c) {
  process_rows_impl(a, row0, row1, c);
}
BENDLAB_LBM_CLONES void process_rows_reg(const StepArgs& a, int row0, int row1, const Regularized& c) {
  process_rows_impl(a, row0, row1, c);
}
void process_rows(const StepArgs& a, int row0, int row1, const Bgk<false>& c) { process_rows_bgk(a, row0, row1, c); }
void process_rows(const StepArgs& a, int row0, int row1, const Bgk<true>& c) { process_rows_bgk1(a, row0, row1, c); }
BENDLAB_LBM_CLONES void process_rows_trt(const StepArgs& a, int row0, int row1, const Trt& c) {
  process_rows_impl(a, row0, row1, c);
}
void process_rows(const StepArgs& a, int row0, int row1, const Regularized& c) { process_rows_reg(a, row0, row1, c); }
void process_rows(const StepArgs& a, int row0, int row1, const Trt& c) { process_rows_trt(a, row0, row1, c); }

}  // namespace

Lattice::Lattice(const LatticeConfig& config) : config_(config) {
  if (config.nx < 1 || config.ny < 1 || config.nz < 1) {
    throw Error(fmt::format("LBM lattice size {} x {} x {} must be positive", config.nx, config.ny, config.nz));
  }
  if (!(config.tau > 0.5) || !std::isfinite(config.tau)) {
    throw Error(fmt::format("LBM relaxation time tau = {} must be finite and exceed 1/2", config.tau));
  }
  if (!std::isfinite(config.wall_velocity)) throw Error("LBM wall velocity is not finite");
  if (config.walls && config.nz < 2) throw Error("LBM lattice between walls needs at least 2 layers in z");
  if (config.ghost_y_layers && config.ny < 3) throw Error("LBM subdomain with ghost layers needs at least 3 layers in y");
  if (!config.body_force.allFinite()) throw Error("LBM body force is not finite");
  if (config.collision == Collision::TRT && !(config.trt_magic > 0 && std::isfinite(config.trt_magic))) {
    throw Error(fmt::format("LBM TRT magic parameter {} must be finite and positive", config.trt_magic));
  }
  collision_ = config.collision;
  if (collision_ == Collision::Auto) collision_ = config.tau == 1.0 ? Collision::BGK : Collision::Regularized;
  n_ = static_cast<std::size_t>(config.nx) * config.ny * config.nz;
  fluid_nodes_ = n_;
  build_section();
  build_pull_rows();
  build_gather_rows();
  // A multiple of 4 KiB (512 doubles) plus 9 cache lines: the slots' starts fall on 19 (and the
  // force components' on 3) different cache-line offsets modulo 4 KiB and modulo any larger power
  // of two up to 9 * 64 lines, so a row's streams neither alias nor share cache sets.
  stride_ = config.pad_slots ? (n_ + 511) / 512 * 512 + 72 : n_;
  f_.assign(kQ * stride_, 0.0);
  force_.assign(3 * stride_, 0.0);
  initialise([](const Vec3&) { return Vec3::Zero(); });
}

void Lattice::build_section() {
  if (!config_.section) return;
  const int ny = config_.ny, nz = config_.nz;
  solid_rows_.assign(static_cast<std::size_t>(ny) * nz, 0);
  std::size_t fluid_rows = 0;
  for (int k = 0; k < nz; ++k) {
    for (int j = 0; j < ny; ++j) {
      const Vec3 x = position(0, j, k);
      const bool solid = config_.section->solid(x.y(), x.z());
      solid_rows_[j + static_cast<std::size_t>(ny) * k] = solid ? 1 : 0;
      fluid_rows += solid ? 0 : 1;
    }
  }
  if (fluid_rows == 0) throw Error(fmt::format("LBM lattice {} x {} x {}: the {} leaves no fluid", config_.nx, ny, nz, config_.section->describe()));
  fluid_nodes_ = fluid_rows * static_cast<std::size_t>(config_.nx);
  // Every link of a fluid row must reach what the section describes at its unwrapped end (the wall
  // fraction is measured along the unwrapped link); where a periodic wrap finds otherwise, the
  // section does not close inside the box.
  // Ghost layers (a subdomain's copies of its neighbours' layers) are never stepped: no links.
  const int jg0 = config_.ghost_y_layers ? 1 : 0, jg1 = config_.ghost_y_layers ? ny - 1 : ny;
  for (int k = 0; k < nz; ++k) {
    for (int j = jg0; j < jg1; ++j) {
      if (solid_rows_[j + static_cast<std::size_t>(ny) * k]) continue;
      for (int q = 1; q < kQ; ++q) {
        if (kCy[q] == 0 && kCz[q] == 0) continue;
        const int jd = j + kCy[q], kd = k + kCz[q];
        if (config_.walls && (kd < 0 || kd >= nz)) continue;  // a flat wall: plain halfway bounce-back
        const bool solid = solid_rows_[wrap(jd, ny) + static_cast<std::size_t>(ny) * wrap(kd, nz)] != 0;
        const Vec3 x = position(0, j, k);
        // A link that wraps around a periodic axis must find there what the section puts beyond
        // the box's edge.
        if (solid != config_.section->solid(x.y() + kCy[q], x.z() + kCz[q])) {
          throw Error(fmt::format("LBM lattice {} x {} x {}: the {} does not close inside the box (fluid row at y = {}, z = {})",
                                  config_.nx, ny, nz, config_.section->describe(), x.y(), x.z()));
        }
        if (!solid) continue;
        const int jb = wrap(j - kCy[q], ny), kb = k - kCz[q];
        const bool back_in_wall = config_.walls && (kb < 0 || kb >= nz);
        const int kbw = wrap(kb, nz);
        const bool back_fluid = !back_in_wall && !solid_rows_[jb + static_cast<std::size_t>(ny) * kbw];
        const double fraction = config_.section->link_fraction(x.y(), x.z(), kCy[q], kCz[q]);
        wall_links_.push_back({j, k, q, fraction, back_fluid, jb, kbw});
      }
    }
  }
  wall_buffer_.resize(wall_links_.size() * static_cast<std::size_t>(config_.nx));
}

void Lattice::build_pull_rows() {
  const int ny = config_.ny, nz = config_.nz;
  pull_rows_.resize(static_cast<std::size_t>(ny) * nz * kQ);
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int q = 0; q < kQ; ++q) {
        std::int32_t& r = pull_rows_[(j + static_cast<std::size_t>(ny) * k) * kQ + q];
        const int ks = k - kCz[q];
        if (config_.walls && (ks < 0 || ks >= nz)) {
          r = ks < 0 ? kPullBottomWall : kPullTopWall;
          continue;
        }
        const int js = wrap(j - kCy[q], ny), kw = wrap(ks, nz);
        r = solid_row(js, kw) ? kPullSolid : static_cast<std::int32_t>(js + ny * kw);
      }
}

void Lattice::build_gather_rows() {
  const std::size_t rows = static_cast<std::size_t>(config_.ny) * static_cast<std::size_t>(config_.nz);
  gather_lo_.resize(rows);
  gather_hi_.resize(rows);
  for (std::size_t r = 0; r < rows; ++r) {
    std::int32_t lo = static_cast<std::int32_t>(r), hi = lo;
    for (int q = 0; q < kQ; ++q) {
      const std::int32_t s = pull_rows_[r * kQ + q];
      if (s < 0) continue;  // a wall or solid: nothing another row writes
      lo = std::min(lo, s);
      hi = std::max(hi, s);
    }
    gather_lo_[r] = lo;
    gather_hi_[r] = hi;
  }
  // The wall pass writes slots of the rows of its links: every row that reads one waits for it.
  // (A row's readers are its source rows' readers' mirror: the 19 directions come in pairs.)
  const int ny = config_.ny;
  for (const WallLink& l : wall_links_) {
    const std::size_t w = static_cast<std::size_t>(l.j) + static_cast<std::size_t>(ny) * static_cast<std::size_t>(l.k);
    gather_hi_[w] = std::numeric_limits<std::int32_t>::max();
    for (int q = 0; q < kQ; ++q) {
      const std::int32_t s = pull_rows_[w * kQ + q];
      if (s >= 0) gather_hi_[static_cast<std::size_t>(s)] = std::numeric_limits<std::int32_t>::max();
    }
  }
}

bool Lattice::is_solid(std::size_t node) const {
  if (solid_rows_.empty()) return false;
  return solid_rows_[node / static_cast<std::size_t>(config_.nx)] != 0;
}

namespace {

// Calls body(i, wrap(i - cx, nx)) for i = 0 .. nx - 1 in order, the wrapped end apart, so that
// the loop over the interior has no wrap and the compiler can vectorise it.
template <class Body>
LBM_INLINE void for_row_with_behind(int nx, int cx, Body&& body) {
  if (cx == 1) {
    body(0, nx - 1);
    for (int i = 1; i < nx; ++i) body(i, i - 1);
  } else if (cx == -1) {
    for (int i = 0; i < nx - 1; ++i) body(i, i + 1);
    body(nx - 1, 0);
  } else {
    for (int i = 0; i < nx; ++i) body(i, i);
  }
}

}  // namespace

// The interpolated bounce-back (Bouzidi et al. 2001, the linear rule) of every wall link, as
// interpolated_bounce_back_reference computes it node by node, with the link's branches taken
// once per row: the same arithmetic in the same order, so the same bits.
void Lattice::apply_interpolated_bounce_back(bool after_odd, int j0, int j1) {
  if (wall_links_.empty() || !config_.interpolated_walls) return;
  if (config_.reference_wall_pass) return interpolated_bounce_back_reference(after_odd, j0, j1);
  const int nx = config_.nx, ny = config_.ny;
  double* f = f_.data();
  const std::size_t S = stride_;
  auto row = [&](int j, int k) { return static_cast<std::size_t>(nx) * (static_cast<std::size_t>(j) + static_cast<std::size_t>(ny) * static_cast<std::size_t>(k)); };
  // Phase 1: every new value from the step's populations (a link's sources may be another link's
  // target in a gap one node wide, so no write before all are read).
  double* buf = wall_buffer_.data();
  for (const WallLink& l : wall_links_) {
    double* out = buf;
    buf += nx;
    if (l.j < j0 || l.j >= j1) continue;
    const int q = l.q, qb = opposite(q);
    const double t = l.fraction;
    const double* target = f + qb * S + row(l.j, l.k);  // f*_q(x_f) after either step (plain bounce-back)
    const double* own_q = f + q * S + row(l.j, l.k);
    if (t < 0.5) {
      if (!l.back_fluid) {
        for (int i = 0; i < nx; ++i) out[i] = target[i];
        continue;
      }
      const double a = 2.0 * t, b = 1.0 - 2.0 * t;
      if (after_odd) {
        for (int i = 0; i < nx; ++i) out[i] = a * target[i] + b * own_q[i];
      } else {
        const double* behind = f + qb * S + row(l.jb, l.kb);  // slot qbar of x_b
        for_row_with_behind(nx, kCx[q], [&](int i, int ib) { out[i] = a * target[i] + b * behind[ib]; });
      }
    } else {
      const double d = 2.0 * t, c = (2.0 * t - 1.0) / (2.0 * t);
      if (after_odd && l.back_fluid) {
        const double* reverse = f + qb * S + row(l.jb, l.kb);  // slot qbar of x_b
        for_row_with_behind(nx, kCx[q], [&](int i, int ib) { out[i] = target[i] / d + c * reverse[ib]; });
      } else {
        for (int i = 0; i < nx; ++i) out[i] = target[i] / d + c * own_q[i];
      }
    }
  }
  // Phase 2: the writes, the rest population taking back the difference (see the reference).
  buf = wall_buffer_.data();
  for (const WallLink& l : wall_links_) {
    const double* in = buf;
    buf += nx;
    if (l.j < j0 || l.j >= j1) continue;
    double* target = f + opposite(l.q) * S + row(l.j, l.k);
    double* rest = f + row(l.j, l.k);
    for (int i = 0; i < nx; ++i) {
      rest[i] -= in[i] - target[i];
      target[i] = in[i];
    }
  }
}

void Lattice::interpolated_bounce_back_reference(bool after_odd, int j0, int j1) {
  const int nx = config_.nx, ny = config_.ny;
  double* f = f_.data();
  const std::size_t S = stride_;
  auto node = [&](int i, int j, int k) { return static_cast<std::size_t>(i) + static_cast<std::size_t>(nx) * (static_cast<std::size_t>(j) + static_cast<std::size_t>(ny) * static_cast<std::size_t>(k)); };
  // Two phases: every new value from the step's populations first, then the writes, since a
  // link's sources may be another link's target in a gap one node wide.
  for (int phase = 0; phase < 2; ++phase) {
    double* buf = wall_buffer_.data();
    for (const WallLink& l : wall_links_) {
      if (l.j < j0 || l.j >= j1) {
        buf += nx;
        continue;
      }
      const int q = l.q, qb = opposite(q);
      const double t = l.fraction;
      for (int i = 0; i < nx; ++i, ++buf) {
        const std::size_t xf = node(i, l.j, l.k);
        double& target = f[qb * S + xf];  // holds f*_q(x_f) after either step (plain bounce-back)
        if (phase == 1) {
          // The interpolation does not conserve mass (plain bounce-back does: it returns what went
          // out); the rest population of the node takes back the difference, which keeps the
          // node's momentum and the wall's order and stops the density drifting over a long run.
          f[xf] -= *buf - target;
          target = *buf;
          continue;
        }
        const std::size_t xb = l.back_fluid ? node(wrap(i - kCx[q], nx), l.jb, l.kb) : xf;
        if (t < 0.5) {
          if (!l.back_fluid) {
            *buf = target;
            continue;
          }
          // f*_q(x_f - c_q): slot qbar of x_b after an even step, pushed into slot q of x_f by an odd one.
          const double behind = after_odd ? f[q * S + xf] : f[qb * S + xb];
          *buf = 2.0 * t * target + (1.0 - 2.0 * t) * behind;
        } else {
          // f*_qbar(x_f): slot q of x_f after an even step; pushed to slot qbar of x_b by an odd
          // one (bounced into slot q of x_f when x_b is solid).
          const double reverse = after_odd && l.back_fluid ? f[qb * S + xb] : f[q * S + xf];
          *buf = target / (2.0 * t) + (2.0 * t - 1.0) / (2.0 * t) * reverse;
        }
      }
    }
  }
}

double Lattice::shear_rate() const { return config_.walls ? 2.0 * config_.wall_velocity / config_.nz : 0.0; }

std::array<int, 3> Lattice::coordinates(std::size_t node) const {
  const int i = static_cast<int>(node % config_.nx);
  const std::size_t r = node / config_.nx;
  return {i, static_cast<int>(r % config_.ny), static_cast<int>(r / config_.ny)};
}

Vec3 Lattice::position(int i, int j, int k) const {
  return {i + 0.5 - 0.5 * config_.nx, j + 0.5 - 0.5 * config_.ny, k + 0.5 - 0.5 * config_.nz};
}

void Lattice::initialise(const std::function<Vec3(const Vec3&)>& velocity,
                         const std::function<double(const Vec3&)>& density,
                         const std::function<Mat3(const Vec3&)>& stress) {
  const double tau = config_.tau;
  for (int k = 0; k < config_.nz; ++k) {
    for (int j = 0; j < config_.ny; ++j) {
      for (int i = 0; i < config_.nx; ++i) {
        const Vec3 x = position(i, j, k);
        const bool solid = solid_row(j, k);  // at rest, never stepped
        const Vec3 u = solid ? Vec3::Zero() : velocity(x);
        const double rho = density && !solid ? density(x) : 1.0;
        Mat3 S = Mat3::Zero();
        if (stress && !solid) S = stress(x);
        const std::size_t node = index(i, j, k);
        for (int q = 0; q < kQ; ++q) {
          double v = equilibrium(q, rho, u.x(), u.y(), u.z());
          if (stress && !solid) {
            const Vec3 c(kCx[q], kCy[q], kCz[q]);
            v -= 3.0 * tau * kW[q] * rho * (c.dot(S * c) - S.trace() / 3.0);
          }
          f_[q * stride_ + node] = v;
        }
      }
    }
  }
  step_ = 0;
}

void Lattice::initialise_shear_flow() {
  const double g = shear_rate();
  Mat3 S = Mat3::Zero();
  S(2, 0) = g;  // d u_x / d z
  initialise([g](const Vec3& x) { return Vec3(g * x.z(), 0.0, 0.0); }, nullptr, [S](const Vec3&) { return S; });
}

void Lattice::clear_force() {
  if (force_everywhere_) {
    std::fill(force_.begin(), force_.end(), 0.0);
  } else {
    double* f = force_.data();
    for (const std::size_t node : forced_) f[node] = f[stride_ + node] = f[2 * stride_ + node] = 0.0;
    for (const NodeRun& run : forced_runs_)
      for (int d = 0; d < 3; ++d) std::fill_n(f + d * stride_ + run.first, run.count, 0.0);
  }
  forced_.clear();
  forced_runs_.clear();
  forced_run_nodes_ = 0;
  force_everywhere_ = false;
}

double* Lattice::force_field_for_writing(const std::vector<NodeRun>& within) {
  if (!force_everywhere_) {
    for (const NodeRun& run : within) forced_run_nodes_ += static_cast<std::size_t>(run.count);
    if (forced_run_nodes_ > n_ / 2) {
      return force_field_for_writing();  // a sweep of the whole field is then the cheaper clear
    }
    forced_runs_.insert(forced_runs_.end(), within.begin(), within.end());
  }
  return force_.data();
}

void Lattice::set_uniform_force(const Vec3& F) {
  for (int d = 0; d < 3; ++d) std::fill_n(force_.begin() + d * stride_, n_, F[d]);
  forced_.clear();
  forced_runs_.clear();
  forced_run_nodes_ = 0;
  force_everywhere_ = true;
}

template <class Coll>
void Lattice::step_with(const Coll& coll, int j0, int j1, const Gather* gather) {
  StepArgs a{f_.data(), stride_, config_.nx, config_.ny, config_.nz, j0, j1 - j0, config_.walls, step_ % 2 == 1,
             config_.wall_velocity, {force_.data(), force_.data() + stride_, force_.data() + 2 * stride_},
             solid_rows_.empty() ? nullptr : solid_rows_.data(),
             {config_.body_force.x(), config_.body_force.y(), config_.body_force.z()}};
  const int rows = (j1 - j0) * config_.nz;
  // Small lattices (tests) step on one thread: a parallel region costs more than their update.
#pragma omp parallel if (n_ >= kParallelNodes)
  {
    const int t = omp_get_thread_num(), nt = omp_get_num_threads();
    const int r0 = static_cast<int>(static_cast<std::int64_t>(rows) * t / nt);
    const int r1 = static_cast<int>(static_cast<std::int64_t>(rows) * (t + 1) / nt);
    if (gather == nullptr) {
      process_rows(a, r0, r1, coll);
    } else {
      gather_while_stepping(a, r0, r1, coll, *gather);
    }
  }
  ++step_;
}

// step_gathering's loop for the rows [r0, r1) of one thread (all layers stepped, j0 = 0): the rows
// a block at a time, and after each block the velocities of the runs whose rows read only rows
// this thread has stepped (gather_lo_, gather_hi_), in the runs' order.
template <class Args, class Coll>
void Lattice::gather_while_stepping(const Args& a, int r0, int r1, const Coll& coll, const Gather& g) const {
  const std::vector<NodeRun>& runs = *g.runs;
  const std::size_t nx = static_cast<std::size_t>(config_.nx);
  const std::int64_t after = step_ + 1;
  auto row_of = [&](std::size_t k) { return static_cast<std::int32_t>(runs[k].first / nx); };
  // The runs of rows [r0, r1).
  std::size_t k = static_cast<std::size_t>(
      std::partition_point(runs.begin(), runs.end(), [&](const NodeRun& run) { return run.first / nx < static_cast<std::size_t>(r0); }) -
      runs.begin());
  const std::size_t k_end = static_cast<std::size_t>(
      std::partition_point(runs.begin(), runs.end(), [&](const NodeRun& run) { return run.first / nx < static_cast<std::size_t>(r1); }) -
      runs.begin());
  // A row reads rows within one layer (ny rows) and one row of itself, wrap apart: once a block
  // ends at e, every row below e - ny - 1 has all its unwrapped sources stepped.
  const int lag = config_.ny + 1;
  constexpr int kBlock = 8;
  for (int b = r0; b < r1; b += kBlock) {
    const int e = std::min(b + kBlock, r1);
    process_rows(a, b, e, coll);
    const bool last = e == r1;
    for (; k < k_end && (last || row_of(k) + lag < e); ++k) {
      const std::int32_t row = row_of(k);
      if (gather_lo_[static_cast<std::size_t>(row)] < r0 || gather_hi_[static_cast<std::size_t>(row)] >= e) continue;
      velocities_of_run_after(runs[k].first, runs[k].count, g.u + 3 * runs[k].first, after);
      g.done[k] = 1;
    }
  }
}

void Lattice::step() { step_layers(0, config_.ny); }

void Lattice::step_gathering(const std::vector<NodeRun>& runs, double* u, std::vector<std::uint8_t>& done) {
  done.assign(runs.size(), 0);
  const Gather g{&runs, u, done.data()};
  collide_stream_layers(0, config_.ny, &g);
  correct_section_walls(0, config_.ny);
}

void Lattice::step_layers(int j0, int j1) {
  collide_stream_layers(j0, j1);
  correct_section_walls(j0, j1);
}

void Lattice::correct_section_walls(int j0, int j1) {
  if (j0 < 0 || j1 > config_.ny || j0 >= j1)
    throw Error(fmt::format("LBM wall pass over layers [{}, {}) outside the lattice's 0..{}", j0, j1, config_.ny));
  if (step_ == 0) throw Error("LBM wall pass before any step");
  apply_interpolated_bounce_back((step_ - 1) % 2 == 1, j0, j1);  // where the last step left its populations
}

void Lattice::collide_stream_layers(int j0, int j1) { collide_stream_layers(j0, j1, nullptr); }

void Lattice::collide_stream_layers(int j0, int j1, const Gather* gather) {
  if (j0 < 0 || j1 > config_.ny || j0 >= j1)
    throw Error(fmt::format("LBM step of layers [{}, {}) outside the lattice's 0..{}", j0, j1, config_.ny));
  const double tau = config_.tau;
  if (collision_ == Collision::BGK && tau == 1.0) {
    step_with(Bgk<true>{1.0, 0.5}, j0, j1, gather);
  } else if (collision_ == Collision::BGK) {
    step_with(Bgk<false>{1.0 / tau, 1.0 - 0.5 / tau}, j0, j1, gather);
  } else if (collision_ == Collision::TRT) {
    // Lambda = (tau - 1/2)(1/omega- - 1/2).
    step_with(Trt{1.0 / tau, 1.0 / (0.5 + config_.trt_magic / (tau - 0.5))}, j0, j1, gather);
  } else {
    step_with(Regularized{1.0 - 1.0 / tau, 1.0 - 0.5 / tau}, j0, j1, gather);
  }
}

void Lattice::populations(std::size_t node, double f[kQ]) const {
  if (step_ % 2 == 0) {
    for (int q = 0; q < kQ; ++q) f[q] = f_[q * stride_ + node];
    return;
  }
  // populations_reference's cases, with the source row of each direction looked up.
  const std::size_t nx = static_cast<std::size_t>(config_.nx);
  const std::size_t row = node / nx;
  const int i = static_cast<int>(node - row * nx);
  const std::int32_t* source = pull_rows_.data() + row * kQ;
  for (int q = 0; q < kQ; ++q) {
    const std::int32_t r = source[q];
    if (r >= 0) {
      int is = i - kCx[q];
      is = is < 0 ? is + config_.nx : (is >= config_.nx ? is - config_.nx : is);
      f[q] = f_[opposite(q) * stride_ + static_cast<std::size_t>(r) * nx + static_cast<std::size_t>(is)];
    } else if (r == kPullSolid) {
      f[q] = f_[q * stride_ + node];
    } else {
      const double uw = r == kPullBottomWall ? -config_.wall_velocity : config_.wall_velocity;
      f[q] = f_[q * stride_ + node] + 6.0 * kW[q] * kCx[q] * uw;
    }
  }
}

void Lattice::populations_reference(std::size_t node, double f[kQ]) const {
  if (step_ % 2 == 0) {
    for (int q = 0; q < kQ; ++q) f[q] = f_[q * stride_ + node];
    return;
  }
  // After an even step slot qbar of node x - c_q holds the post-collision f_q of that node.
  const auto [i, j, k] = coordinates(node);
  for (int q = 0; q < kQ; ++q) {
    const int ks = k - kCz[q];
    if (config_.walls && (ks < 0 || ks >= config_.nz)) {
      const double uw = ks < 0 ? -config_.wall_velocity : config_.wall_velocity;
      f[q] = f_[q * stride_ + node] + 6.0 * kW[q] * kCx[q] * uw;
    } else {
      const int js = wrap(j - kCy[q], config_.ny), kw = wrap(ks, config_.nz);
      if (solid_row(js, kw)) {
        f[q] = f_[q * stride_ + node];  // bounced back (and interpolated) after the even step
        continue;
      }
      const std::size_t src = index(wrap(i - kCx[q], config_.nx), js, kw);
      f[q] = f_[opposite(q) * stride_ + src];
    }
  }
}

double Lattice::density(std::size_t node) const {
  if (is_solid(node)) return 1.0;  // the resting wall holds no fluid (lattice.hpp)
  double f[kQ];
  populations(node, f);
  double rho = 0;
  for (int q = 0; q < kQ; ++q) rho += f[q];
  return rho;
}

Vec3 Lattice::velocity(std::size_t node) const {
  if (is_solid(node)) return Vec3::Zero();  // the resting wall
  double f[kQ];
  populations(node, f);
  double rho = 0;
  Vec3 j = Vec3::Zero();
  for (int q = 0; q < kQ; ++q) {
    rho += f[q];
    j += f[q] * Vec3(kCx[q], kCy[q], kCz[q]);
  }
  return (j + 0.5 * (force(node) + config_.body_force)) / rho;
}

namespace {

// velocities_of_run's sums for nodes t and t + 1 (t only with lanes = 1), from slot q on: rho and j
// of velocity(), leaving out the terms with c = 0 (adding f * 0 to a sum that starts at +0 never
// changes it) and subtracting for c = -1 (j + f * (-1) is j - f exactly).
template <int q>
[[gnu::always_inline]] inline void add_moments(const double* const* p, int t, double* rho, double* jx, double* jy, double* jz, int lanes = 2) {
  if constexpr (q < kQ) {
    for (int k = 0; k < 2; ++k) {
      const double v = k < lanes ? p[q][t + k] : 0.0;
      rho[k] += v;
      if constexpr (kCx[q] == 1) jx[k] += v;
      if constexpr (kCx[q] == -1) jx[k] -= v;
      if constexpr (kCy[q] == 1) jy[k] += v;
      if constexpr (kCy[q] == -1) jy[k] -= v;
      if constexpr (kCz[q] == 1) jz[k] += v;
      if constexpr (kCz[q] == -1) jz[k] -= v;
    }
    add_moments<q + 1>(p, t, rho, jx, jy, jz, lanes);
  }
}

}  // namespace

void Lattice::velocities_of_run(std::size_t node, int count, double* u) const { velocities_of_run_after(node, count, u, step_); }

void Lattice::velocities_of_run_after(std::size_t node, int count, double* u, std::int64_t steps) const {
  const std::size_t nx = static_cast<std::size_t>(config_.nx);
  const std::size_t row = node / nx;
  const int i0 = static_cast<int>(node - row * nx);
  if (count < 0 || i0 + count > config_.nx) throw Error(fmt::format("lattice: a run of {} nodes from x = {} leaves its row", count, i0));
  if (solid_row(static_cast<int>(row % static_cast<std::size_t>(config_.ny)), static_cast<int>(row / static_cast<std::size_t>(config_.ny)))) {
    std::fill_n(u, 3 * count, 0.0);  // the resting wall, as velocity()
    return;
  }
  // velocity()'s arithmetic node by node, a chunk of the run at a time. The 19 populations of the
  // chunk's nodes are found first (contiguous in each slot, but for the x-wrap of an odd step at
  // the row's two ends, copied to a buffer), then each node's moments are summed over q in
  // velocity()'s order in registers. Terms with c = 0 are left out and c = -1 subtracts: the
  // sums start at +0, so adding f * 0 never changes them, and j + f * (-1) is j - f exactly.
  constexpr int kChunk = 64;
  double buffer[kQ][kChunk];
  const double* p[kQ];
  const std::int32_t* source = pull_rows_.data() + row * kQ;
  const bool odd = steps % 2 == 1;
  for (int c0 = 0; c0 < count; c0 += kChunk) {
    const int m = std::min(kChunk, count - c0);
    const int i = i0 + c0;  // x of the chunk's first node
    const std::size_t first = row * nx + static_cast<std::size_t>(i);
    for (int q = 0; q < kQ; ++q) {
      p[q] = f_.data() + q * stride_ + first;  // even step, solid source, wall
      const std::int32_t r = odd ? source[q] : kPullSolid;
      if (r >= 0) {
        // Slot qbar of the source row at x - c_qx, wrapped along x.
        const double* src = f_.data() + opposite(q) * stride_ + static_cast<std::size_t>(r) * nx;
        if (i - kCx[q] >= 0 && i + m - 1 - kCx[q] < config_.nx) {
          p[q] = src + (i - kCx[q]);
        } else {
          for (int t = 0; t < m; ++t) {
            int is = i + t - kCx[q];
            is = is < 0 ? is + config_.nx : (is >= config_.nx ? is - config_.nx : is);
            buffer[q][t] = src[is];
          }
          p[q] = buffer[q];
        }
      } else if (r != kPullSolid) {
        const double uw = r == kPullBottomWall ? -config_.wall_velocity : config_.wall_velocity;
        for (int t = 0; t < m; ++t) buffer[q][t] = p[q][t] + 6.0 * kW[q] * kCx[q] * uw;
        p[q] = buffer[q];
      }
    }
    const double* Fx = force_.data() + first;
    const double* Fy = Fx + stride_;
    const double* Fz = Fy + stride_;
    const Vec3& g = config_.body_force;
    // Each node's sums over q in velocity()'s order, nodes in pairs (a vector's lanes): all 19
    // slots advance together along the run, as in the collision kernel, which the hardware's
    // prefetch follows.
    int t = 0;
    for (; t + 2 <= m; t += 2) {
      double rho[2] = {0.0, 0.0}, jx[2] = {0.0, 0.0}, jy[2] = {0.0, 0.0}, jz[2] = {0.0, 0.0};
      add_moments<0>(p, t, rho, jx, jy, jz);
      for (int k = 0; k < 2; ++k) {
        double* ut = u + 3 * (c0 + t + k);
        ut[0] = (jx[k] + 0.5 * (Fx[t + k] + g.x())) / rho[k];
        ut[1] = (jy[k] + 0.5 * (Fy[t + k] + g.y())) / rho[k];
        ut[2] = (jz[k] + 0.5 * (Fz[t + k] + g.z())) / rho[k];
      }
    }
    for (; t < m; ++t) {
      double rho[2] = {0.0, 0.0}, jx[2] = {0.0, 0.0}, jy[2] = {0.0, 0.0}, jz[2] = {0.0, 0.0};
      add_moments<0>(p, t, rho, jx, jy, jz, 1);
      double* ut = u + 3 * (c0 + t);
      ut[0] = (jx[0] + 0.5 * (Fx[t] + g.x())) / rho[0];
      ut[1] = (jy[0] + 0.5 * (Fy[t] + g.y())) / rho[0];
      ut[2] = (jz[0] + 0.5 * (Fz[t] + g.z())) / rho[0];
    }
  }
}

double Lattice::total_mass() const {
  double m = 0;
  for (std::size_t node = 0; node < n_; ++node) {
    if (!is_solid(node)) m += density(node);
  }
  return m;
}

Vec3 Lattice::total_momentum() const {
  Vec3 p = Vec3::Zero();
  double f[kQ];
  for (std::size_t node = 0; node < n_; ++node) {
    if (is_solid(node)) continue;
    populations(node, f);
    for (int q = 0; q < kQ; ++q) p += f[q] * Vec3(kCx[q], kCy[q], kCz[q]);
  }
  return p;
}

std::vector<double> Lattice::raw_populations() const {
  std::vector<double> packed(kQ * n_);
  for (int q = 0; q < kQ; ++q) std::copy_n(f_.begin() + q * stride_, n_, packed.begin() + q * n_);
  return packed;
}

void Lattice::restore_raw(const std::vector<double>& populations, std::int64_t step) {
  if (populations.size() != kQ * n_) {
    throw Error(fmt::format("LBM state has {} populations, the lattice needs {}", populations.size(), kQ * n_));
  }
  if (step < 0) throw Error(fmt::format("LBM step count {} is negative", step));
  for (int q = 0; q < kQ; ++q) std::copy_n(populations.begin() + q * n_, n_, f_.begin() + q * stride_);
  step_ = step;
}

}  // namespace bendlab::lbm
