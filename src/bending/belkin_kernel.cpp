// The kernels of belkin_kernel.hpp: the loop bodies, written once as templates, and the functions
// compiled from them for each instruction set.
#include "bendlab/bending/belkin_kernel.hpp"

namespace bendlab::belkin_kernel {

namespace {

enum class Field { scalar, positions };

// The reference form's kernel. Sum over the points of the runs [runs[2r], runs[2r + 1]), r < nruns, of
// A_p exp(-|p - x_i|^2 / (4 a_i)) (w(p) - w(x_i)) for the kept terms (exponent <= emax, and p
// above the plane of x_i under the half-space rule), into acc. Branch-free: blocks of kLanes
// points (the point arrays are padded by kLanes entries), points past the run's end and masked
// terms weighing 0, so that the block vectorises whole, with no scalar remainder, and the lanes
// are summed once per vertex.
template <int Cols>
__attribute__((always_inline)) inline void run_sum_body(const KernelInput& in, const int* runs, int nruns,
                                                        double* acc) {
  const double *sx = in.sx, *sy = in.sy, *sz = in.sz, *sn = in.sn, *sl = in.sl;
  const double *w0 = in.w[0], *w1 = in.w[1], *w2 = in.w[2];
  const double xi = in.xi, yi = in.yi, zi = in.zi, margin = in.margin, inv4a = in.inv4a, emax = in.emax;
  const double wi0 = in.wi[0], wi1 = in.wi[1], wi2 = in.wi[2];
  const bool all_sides = !in.half_space;
  double a0[kLanes] = {}, a1[kLanes] = {}, a2[kLanes] = {};
  for (int r = 0; r < nruns; ++r) {
    const int k1 = runs[2 * r + 1];
    for (int k0 = runs[2 * r]; k0 < k1; k0 += kLanes) {
#pragma omp simd
      for (int l = 0; l < kLanes; ++l) {
        const int k = k0 + l;
        const double dx = sx[k] - xi, dy = sy[k] - yi, dz = sz[k] - zi;
        const double e = (dx * dx + dy * dy + dz * dz) * inv4a;
        // (p - c).(x_i - c) > 0: p lies above the plane through c with normal x_i - c.
        const bool above = sx[k] * xi + sy[k] * yi + sz[k] * zi > margin * sn[k];
        const double lump = sl[k];
        const bool keep = (above | all_sides) & (e <= emax) & (k < k1);
        const double weight = (keep ? lump : 0.0) * exp_neg(std::min(e, emax));
        a0[l] += weight * (w0[k] - wi0);
        if constexpr (Cols > 1) a1[l] += weight * (w1[k] - wi1);
        if constexpr (Cols > 2) a2[l] += weight * (w2[k] - wi2);
      }
    }
  }
  for (int l = 0; l < kLanes; ++l) {
    acc[0] += a0[l];
    if constexpr (Cols > 1) acc[1] += a1[l];
    if constexpr (Cols > 2) acc[2] += a2[l];
  }
}

// The grid form's kernel: the sum of eq. (13) for one vertex over its runs, as run_sum_body but
// in blocks of Lanes (one vector register: 8 with AVX-512, 4 with AVX2; the runs are short, about
// 35 points, so wider blocks waste lanes at the run ends: measured 7 % slower with 8 on AVX2), with the
// exponent in base 2 (y = |p - x_i|^2 log2(e) / (4 a_i), kept where y <= ymax, exp2_neg), the
// half-space test only where the vertex's ball crosses the plane (Plane), and for
// Field::positions w(p) - w(x_i) = p - x_i, the differences the distance is made of (Lap x).
// Store: also write the weight of every lane of every block, in scan order, to out (zero for the
// lanes it drops), so that later applies to the same shape need no exponential
// (BelkinLaplacian::weights_, grid_cached_body).
template <Field Kind, bool Plane, int kGridLanes, bool Store = false>
__attribute__((always_inline)) inline void grid_sum_body(const GridInput& in, const int* runs, int nruns,
                                                         double* acc, double* __restrict out = nullptr) {
  const double *sx = in.sx, *sy = in.sy, *sz = in.sz, *sn = in.sn, *sl = in.sl, *w = in.w;
  const double xi = in.xi, yi = in.yi, zi = in.zi, margin = in.margin, scale = in.scale, ymax = in.ymax;
  const double wi = in.wi;
  double a0[kGridLanes] = {}, a1[kGridLanes] = {}, a2[kGridLanes] = {};
  for (int r = 0; r < nruns; ++r) {
    // 64-bit indices: with 32-bit ones the vectoriser picks 256-bit registers for 8 lanes.
    const std::int64_t k1 = runs[2 * r + 1];
    for (std::int64_t k0 = runs[2 * r]; k0 < k1; k0 += kGridLanes) {
#pragma omp simd
      for (std::int64_t l = 0; l < kGridLanes; ++l) {
        const std::int64_t k = k0 + l;
        const double dx = sx[k] - xi, dy = sy[k] - yi, dz = sz[k] - zi;
        const double y = (dx * dx + dy * dy + dz * dz) * scale;
        bool keep = (y <= ymax) & (k < k1);
        if constexpr (Plane) keep = keep & (sx[k] * xi + sy[k] * yi + sz[k] * zi > margin * sn[k]);
        const double lump = sl[k], kernel = exp2_neg(std::min(y, ymax));
        const double weight = (keep ? lump : 0.0) * kernel;
        if constexpr (Store) out[l] = weight;
        if constexpr (Kind == Field::scalar) {
          a0[l] += weight * (w[k] - wi);
        } else {
          a0[l] += weight * dx;
          a1[l] += weight * dy;
          a2[l] += weight * dz;
        }
      }
      if constexpr (Store) out += kGridLanes;
    }
  }
  for (int l = 0; l < kGridLanes; ++l) {
    acc[0] += a0[l];
    if constexpr (Kind == Field::positions) {
      acc[1] += a1[l];
      acc[2] += a2[l];
    }
  }
}

// grid_sum_body for a scalar field with the weights it stored (Store) read back: the same terms,
// summed in the same order. (Lap x is summed where the weights are stored.)
template <int kGridLanes>
__attribute__((always_inline)) inline void grid_cached_body(const GridInput& in, const int* runs, int nruns,
                                                            const double* __restrict wt, double* acc) {
  const double* w = in.w;
  const double wi = in.wi;
  double a0[kGridLanes] = {};
  for (int r = 0; r < nruns; ++r) {
    const std::int64_t k1 = runs[2 * r + 1];
    for (std::int64_t k0 = runs[2 * r]; k0 < k1; k0 += kGridLanes, wt += kGridLanes) {
#pragma omp simd
      for (std::int64_t l = 0; l < kGridLanes; ++l) {
        const std::int64_t k = k0 + l;
        a0[l] += wt[l] * (w[k] - wi);
      }
    }
  }
  for (int l = 0; l < kGridLanes; ++l) acc[0] += a0[l];
}

}  // namespace

// Compiled for AVX-512, AVX2+FMA and baseline x86-64 and picked at run time (as the boundary
// integral's kernels, stokeslet_sums.cpp).
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__) && !defined(__SANITIZE_ADDRESS__)
#define BENDLAB_KERNEL_CLONES __attribute__((target_clones("arch=x86-64-v4", "arch=x86-64-v3", "default")))
#else
#define BENDLAB_KERNEL_CLONES
#endif
BENDLAB_KERNEL_CLONES void run_sum1(const KernelInput& in, const int* runs, int nruns, double* acc) {
  run_sum_body<1>(in, runs, nruns, acc);
}
BENDLAB_KERNEL_CLONES void run_sum3(const KernelInput& in, const int* runs, int nruns, double* acc) {
  run_sum_body<3>(in, runs, nruns, acc);
}
// The grid kernels in blocks of 8 lanes (used where AVX-512 is available) and of 4: each a
// function of its own, so that target_clones compiles it for every instruction set.
#define BENDLAB_GRID_KERNEL(name, kind, plane, lanes)                                            \
  BENDLAB_KERNEL_CLONES void name(const GridInput& in, const int* runs, int nruns, double* acc) { \
    grid_sum_body<kind, plane, lanes>(in, runs, nruns, acc);                                     \
  }
BENDLAB_GRID_KERNEL(grid_sum_scalar8, Field::scalar, false, 8)
BENDLAB_GRID_KERNEL(grid_sum_scalar_plane8, Field::scalar, true, 8)
BENDLAB_GRID_KERNEL(grid_sum_positions8, Field::positions, false, 8)
BENDLAB_GRID_KERNEL(grid_sum_positions_plane8, Field::positions, true, 8)
BENDLAB_GRID_KERNEL(grid_sum_scalar4, Field::scalar, false, 4)
BENDLAB_GRID_KERNEL(grid_sum_scalar_plane4, Field::scalar, true, 4)
BENDLAB_GRID_KERNEL(grid_sum_positions4, Field::positions, false, 4)
BENDLAB_GRID_KERNEL(grid_sum_positions_plane4, Field::positions, true, 4)
#undef BENDLAB_GRID_KERNEL
#define BENDLAB_WEIGHT_KERNEL(name, plane, lanes)                                                              \
  BENDLAB_KERNEL_CLONES void name(const GridInput& in, const int* runs, int nruns, double* out, double* acc) { \
    grid_sum_body<Field::positions, plane, lanes, true>(in, runs, nruns, acc, out);                            \
  }
#define BENDLAB_CACHED_KERNEL(name, lanes)                                                                         \
  BENDLAB_KERNEL_CLONES void name(const GridInput& in, const int* runs, int nruns, const double* wt, double* acc) { \
    grid_cached_body<lanes>(in, runs, nruns, wt, acc);                                                             \
  }
BENDLAB_WEIGHT_KERNEL(grid_weights8, false, 8)
BENDLAB_WEIGHT_KERNEL(grid_weights_plane8, true, 8)
BENDLAB_WEIGHT_KERNEL(grid_weights4, false, 4)
BENDLAB_WEIGHT_KERNEL(grid_weights_plane4, true, 4)
BENDLAB_CACHED_KERNEL(grid_cached_scalar8, 8)
BENDLAB_CACHED_KERNEL(grid_cached_scalar4, 4)
#undef BENDLAB_WEIGHT_KERNEL
#undef BENDLAB_CACHED_KERNEL
const GridKernels& grid_kernels() {
  static const GridKernels kernels = [] {
#if defined(__x86_64__) && defined(__GNUC__)
    const bool wide = __builtin_cpu_supports("avx512f");
#else
    const bool wide = true;
#endif
    return wide ? GridKernels{{{grid_sum_scalar8, grid_sum_scalar_plane8}, {grid_sum_positions8, grid_sum_positions_plane8}},
                              {grid_weights8, grid_weights_plane8},
                              grid_cached_scalar8,
                              8}
                : GridKernels{{{grid_sum_scalar4, grid_sum_scalar_plane4}, {grid_sum_positions4, grid_sum_positions_plane4}},
                              {grid_weights4, grid_weights_plane4},
                              grid_cached_scalar4,
                              4};
  }();
  return kernels;
}

}  // namespace bendlab::belkin_kernel
