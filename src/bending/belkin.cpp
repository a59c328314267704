#include "bendlab/bending/belkin.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numeric>
#include <string>
#include <utility>

#include <omp.h>

#include "bendlab/bending/variational_assembly.hpp"
#include "bendlab/geometry/measures.hpp"

namespace bendlab {

namespace {
constexpr double kLog2e = 1.4426950408889634074;
// Terms with |p - x_i|^2 / (4 a_i) above this are skipped; see the bound in belkin.hpp.
constexpr double kMaxExponent = 80.0;
// A point p counts as above the plane of x_i when (p - c).(x_i - c) > kPlaneTolerance |p - c| |x_i - c|.
// Symmetric meshes put nodes exactly on the plane (the rim of a red blood cell for a node at a
// dimple centre); without the margin, rounding in c would decide whether those nodes count, so
// the result would change under a rotation or a scaling of the shape. Such nodes are left out, as
// the strict inequality of the rule says for points on the plane.
constexpr double kPlaneTolerance = 1e-9;
// The grid form's cells are this many times shorter along x (the rows) than across (build_grid).
constexpr double kRowCellDivisor = 2.0;

// exp(-e) for 0 <= e <= 80 (the kept terms), branch-free so that the kernel loop vectorises:
// -e = n ln 2 + r with n = round(-e / ln 2) (|n| <= 116, so 2^n is a normal double) and
// |r| <= ln 2 / 2 (Cody-Waite: ln 2 split in a part exact in n * ln2_hi and the rest); e^r by its
// Taylor polynomial of degree 13 (remainder below 2e-16 relative); 2^n put into the exponent
// bits. Relative error a few units in the last place, as std::exp's.
inline double exp_neg(double e) {
  constexpr double log2e = 1.4426950408889634074;
  constexpr double ln2_hi = 6.93145751953125e-1, ln2_lo = 1.42860682030941723212e-6;
  constexpr double shifter = 6755399441055744.0;  // 1.5 * 2^52: adding it rounds to an integer
  const double t = -e * log2e + shifter;
  const double n = t - shifter;
  const double r = (-e - n * ln2_hi) - n * ln2_lo;
  double p = 1.0 / 6227020800.0;  // 1/13!
  p = p * r + 1.0 / 479001600.0;
  p = p * r + 1.0 / 39916800.0;
  p = p * r + 1.0 / 3628800.0;
  p = p * r + 1.0 / 362880.0;
  p = p * r + 1.0 / 40320.0;
  p = p * r + 1.0 / 5040.0;
  p = p * r + 1.0 / 720.0;
  p = p * r + 1.0 / 120.0;
  p = p * r + 1.0 / 24.0;
  p = p * r + 1.0 / 6.0;
  p = p * r + 0.5;
  p = p * r + 1.0;
  p = p * r + 1.0;
  // The low bits of t hold n (two's complement); n + 1023 shifted into the exponent field is 2^n.
  const std::uint64_t bits = (std::bit_cast<std::uint64_t>(t) + 1023) << 52;
  return p * std::bit_cast<double>(bits);
}

// What the kernel loop of one vertex reads.
struct KernelInput {
  const double *sx, *sy, *sz, *sn, *sl;  // points in scan order: centred position, |x_p - c|, lumped area
  const double* w[3];                    // the fields in scan order
  double xi, yi, zi, margin, inv4a, emax;
  double wi[3];
  bool half_space;
};

// The reference form's kernel. Sum over the points of the runs [runs[2r], runs[2r + 1]), r < nruns, of
// A_p exp(-|p - x_i|^2 / (4 a_i)) (w(p) - w(x_i)) for the kept terms (exponent <= emax, and p
// above the plane of x_i under the half-space rule), into acc. Branch-free: blocks of kLanes
// points (the point arrays are padded by kLanes entries), points past the run's end and masked
// terms weighing 0, so that the block vectorises whole, with no scalar remainder, and the lanes
// are summed once per vertex.
constexpr int kLanes = 16;
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

// 2^-y for 0 <= y <= 116 (the grid form's kernel weights, y = exponent / ln 2), branch-free:
// y = m + g with m = round(y) (so 2^-m is a normal double) and |g| <= 1/2 exact (Sterbenz);
// 2^-g = exp(u), u = -g ln 2 in [-ln 2 / 2, ln 2 / 2], by the degree-9 polynomial interpolating
// exp at the Chebyshev points of that interval (coefficients from numpy's chebinterpolate,
// converted to powers of u): relative error within 2.3e-14 (measured against exp2l on 2e7
// points of [0, 116]), against which the grid form's 1e-8 agreement with the reference has ample room
// (the reference keeps exp_neg above, within an ulp). 2^-m put into the exponent bits.
inline double exp2_neg(double y) {
  constexpr double shifter = 6755399441055744.0;  // 1.5 * 2^52: adding it rounds to an integer
  const double t = shifter - y;                   // low bits: -m (two's complement)
  const double g = (t - shifter) + y;             // -m + y = g, exact
  const double u = -g * 0.69314718055994530942;   // -g ln 2
  // Estrin's scheme: a dependency chain of 4 multiply-adds instead of Horner's 9, so that the
  // short runs of the kernel loop are not latency-bound.
  const double u2 = u * u, u4 = u2 * u2, u8 = u4 * u4;
  const double p01 = 1.000000000000013 + 1.0000000000000002 * u;
  const double p23 = 0.4999999999944954 + 0.16666666666626692 * u;
  const double p45 = 0.04166666703318375 + 0.008333333360990468 * u;
  const double p67 = 0.0013888803088674226 + 0.00019841202022427646 * u;
  const double p89 = 2.488377337960311e-05 + 2.7626751247900033e-06 * u;
  const double p = (p01 + p23 * u2) + (p45 + p67 * u2) * u4 + p89 * u8;
  const std::uint64_t bits = (std::bit_cast<std::uint64_t>(t) + 1023) << 52;
  return p * std::bit_cast<double>(bits);
}

// What the grid form's kernel reads for one vertex.
struct GridInput {
  const double *sx, *sy, *sz, *sn, *sl;  // points in scan order: centred position, |x_p - c|, lumped area
  const double* w;                       // a scalar field in scan order (Field::scalar)
  double xi, yi, zi, margin, scale, ymax, wi;
};
enum class Field { scalar, positions };

// The kernels' input: the point arrays and a field in scan order (w, or null), ...
GridInput grid_input(const double* sx, const double* sy, const double* sz, const double* sn, const double* sl,
                     const double* w, double max_exponent) {
  GridInput in{};
  in.sx = sx, in.sy = sy, in.sz = sz, in.sn = sn, in.sl = sl, in.w = w;
  in.ymax = max_exponent * kLog2e;
  return in;
}
// ... and vertex i's part: its centred position, |x_i - c|, a_i and the field there.
void set_vertex(GridInput& in, double x, double y, double z, double norm, double a, double wi) {
  in.xi = x, in.yi = y, in.zi = z;
  in.margin = kPlaneTolerance * norm;
  in.scale = kLog2e / (4.0 * a);
  in.wi = wi;
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

// Compiled for AVX-512, AVX2+FMA and baseline x86-64 and picked at run time (as the boundary
// integral's kernel, stokes_single_layer.cpp).
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
using GridKernel = void (*)(const GridInput&, const int*, int, double*);
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
using WeightKernel = void (*)(const GridInput&, const int*, int, double*, double*);
using CachedKernel = void (*)(const GridInput&, const int*, int, const double*, double*);
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
// k[field][plane]: field 0 scalar, 1 positions; weights[plane]; cached (scalar); the block width
// (lanes) of the processor's widest vectors.
struct GridKernels {
  GridKernel k[2][2];
  WeightKernel weights[2];
  CachedKernel cached;
  int lanes;
};
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

// The largest weight buffer a BelkinLaplacian of this thread released (~BelkinLaplacian): a
// shape's weights reuse its pages, which on some virtual machines cost more to touch afresh
// (tens of microseconds per 4 KiB page) than the sums that fill them.
struct SpareWeights {
  std::unique_ptr<double[]> data;
  std::size_t capacity = 0;
};
thread_local SpareWeights spare_weights;

// A 64-byte aligned position in a buffer of doubles with 8 spare entries at its start.
inline double* aligned64(double* p) {
  return p + (64 - reinterpret_cast<std::uintptr_t>(p) % 64) % 64 / sizeof(double);
}
inline const double* aligned64(const double* p) { return aligned64(const_cast<double*>(p)); }
}  // namespace

BelkinLaplacian::BelkinLaplacian(const Topology& topology, const Points& x, const MeshGeometry& geometry,
                                 BelkinOptions options) {
  prepare(topology, x, geometry, options);
}

void BelkinLaplacian::prepare(const Topology& topology, const Points& x, const MeshGeometry& geometry,
                              BelkinOptions options) {
  options_ = options;
  n_ = topology.num_vertices();
  has_weights_ = false;
  const Vec3 c = volume_centroid(topology, x);
  qx_.resize(n_);
  qy_.resize(n_);
  qz_.resize(n_);
  qnorm_.resize(n_);
  for (int p = 0; p < n_; ++p) {
    qx_[p] = x(p, 0) - c.x();
    qy_[p] = x(p, 1) - c.y();
    qz_[p] = x(p, 2) - c.z();
    qnorm_[p] = std::sqrt(qx_[p] * qx_[p] + qy_[p] * qy_[p] + qz_[p] * qz_[p]);
  }
  // sum_t A_t/3 sum_{p in V(t)} of eq. (13) regrouped by vertex.
  lumped_area_ = Scalars::Zero(n_);
  const Faces& F = topology.faces();
  for (int f = 0; f < topology.num_faces(); ++f)
    for (int k = 0; k < 3; ++k) lumped_area_[F(f, k)] += geometry.face_area[f] / 3.0;
  kernel_area_ = geometry.mixed_area;
  // The point arrays, each padded by kLanes zeros (the kernels read whole blocks), an odd number
  // of cache lines apart (arrays a multiple of 4 KiB apart make the kernels' loads of one point
  // collide in the cache).
  stride_ = (static_cast<std::size_t>(n_) + kLanes + 7) / 8 * 8;
  if (stride_ / 8 % 2 == 0) stride_ += 8;
  points_.assign(5 * stride_ + 8, 0.0);
  if (options_.neighbours == BelkinOptions::Neighbours::grid) {
    if (!(options_.kernel_cutoff > 0) || !(options_.kernel_cutoff < 1))
      throw Error("belkin_laplacian: kernel_cutoff must be in (0, 1), got " + std::to_string(options_.kernel_cutoff));
    max_exponent_ = std::min(kMaxExponent, -std::log(options_.kernel_cutoff));
    build_grid();
  } else {
    // The reference: every vertex scans every point, in vertex order (one run).
    max_exponent_ = kMaxExponent;
    order_.resize(n_);
    for (int p = 0; p < n_; ++p) order_[p] = p;
    runs_.assign({0, n_});
    run_shared_ = true;
  }
  double* arrays = aligned64(points_.data());
  for (int k = 0; k < n_; ++k) {
    const int p = order_[k];
    arrays[k] = qx_[p];
    arrays[stride_ + k] = qy_[p];
    arrays[2 * stride_ + k] = qz_[p];
    arrays[3 * stride_ + k] = qnorm_[p];
    arrays[4 * stride_ + k] = lumped_area_[p];
  }
  if (!run_shared_) cache_weights();
}

BelkinLaplacian::~BelkinLaplacian() {
  if (weights_.data && weights_.capacity >= spare_weights.capacity) {
    spare_weights.data = std::move(weights_.data);
    spare_weights.capacity = weights_.capacity;
  }
}

void BelkinLaplacian::cache_weights() {
  const GridKernels& kernels = grid_kernels();
  const int lanes = kernels.lanes;
  std::vector<std::size_t>& start = weight_start_;
  start.assign(static_cast<std::size_t>(n_) + 1, 0);
  for (int i = 0; i < n_; ++i) {
    std::size_t count = 0;
    for (int r = run_start_[i]; r < run_start_[i + 1]; r += 2)
      count += static_cast<std::size_t>((runs_[r + 1] - runs_[r] + lanes - 1) / lanes * lanes);
    start[i + 1] = start[i] + count;
  }
  if (start[n_] > options_.weight_cache_bytes / sizeof(double)) return;
  // Not zeroed: the pass below writes every entry before any apply reads it. The buffer of the
  // previous shape when it is large enough, else this thread's spare, else a new one.
  const std::size_t need = std::max<std::size_t>(weight_start_[n_], 1);
  if (weights_.capacity < need) {
    if (spare_weights.capacity >= need) {
      weights_.data = std::move(spare_weights.data);
      weights_.capacity = std::exchange(spare_weights.capacity, 0);
    } else {
      weights_.data.reset(new double[need]);
      weights_.capacity = need;
    }
  }
  has_weights_ = true;
  GridInput in = grid_input(point_array(0), point_array(1), point_array(2), point_array(3), point_array(4), nullptr,
                            max_exponent_);
  lap_positions_.resize(n_, 3);
#pragma omp parallel for schedule(dynamic, 64) firstprivate(in)
  for (int i = 0; i < n_; ++i) {
    set_vertex(in, qx_[i], qy_[i], qz_[i], qnorm_[i], kernel_area_[i], 0.0);
    double acc[3] = {0, 0, 0};
    kernels.weights[plane_test_[i] ? 1 : 0](in, runs_.data() + run_start_[i], (run_start_[i + 1] - run_start_[i]) / 2,
                                            weights_.data.get() + weight_start_[i], acc);
    const double a = kernel_area_[i];
    const double scale = 1.0 / (4.0 * M_PI * a * a);  // eq. (13) prefactor
    for (int col = 0; col < 3; ++col) lap_positions_(i, col) = scale * acc[col];
  }
}

const double* BelkinLaplacian::point_array(int j) const { return aligned64(points_.data()) + j * stride_; }

void BelkinLaplacian::build_grid() {
  if (n_ == 0) {
    run_start_.assign(1, 0);
    return;
  }
  // Cells of 0.35 times the median cut-off radius across the rows (y, z) and half that along them
  // (x): a vertex scans the rows of cells that meet its ball; smaller cells read fewer points
  // outside the ball (measured at 81920 triangles with cubic cells: 680 points per vertex at 0.35,
  // 800 at 0.5, about 440 inside the ball) but make more, shorter runs, and more rows to list.
  // Shorter cells along x only trim the ends of the runs, at no cost in rows (measured: the two
  // applies 4 to 15 % faster than with cubic cells; 0.35 across measured best among 0.3 to 0.6).
  GridBuffers& gb = grid_buffers_;
  std::vector<double>& r = gb.radius;
  r.resize(n_);
  for (int i = 0; i < n_; ++i) r[i] = std::sqrt(4.0 * kernel_area_[i] * max_exponent_);
  std::vector<double>& sorted = gb.sorted;
  sorted.assign(r.begin(), r.end());
  std::nth_element(sorted.begin(), sorted.begin() + n_ / 2, sorted.end());
  double cell = 0.35 * sorted[n_ / 2];
  double hi[3];
  for (int d = 0; d < 3; ++d) {
    const std::vector<double>& q = d == 0 ? qx_ : d == 1 ? qy_ : qz_;
    lo_[d] = *std::min_element(q.begin(), q.end());
    hi[d] = *std::max_element(q.begin(), q.end());
  }
  // At most about 4 cells per vertex (and 1024 per axis), whatever the spread of a_i.
  const double max_cells = 4.0 * n_ + 64;
  for (;;) {
    const double side[3] = {cell / kRowCellDivisor, cell, cell};
    double count = 1;
    for (int d = 0; d < 3; ++d) count *= std::floor((hi[d] - lo_[d]) / side[d]) + 1;
    bool ok = count <= max_cells && cell > 0;
    for (int d = 0; d < 3; ++d) ok = ok && (hi[d] - lo_[d]) / side[d] < 1023;
    if (ok) break;
    cell = cell > 0 ? 1.25 * cell : 1.0;
  }
  cell_[0] = cell / kRowCellDivisor, cell_[1] = cell, cell_[2] = cell;
  for (int d = 0; d < 3; ++d) dims_[d] = static_cast<int>(std::floor((hi[d] - lo_[d]) / cell_[d])) + 1;
  auto coord = [&](double v, int d) { return std::clamp(static_cast<int>(std::floor((v - lo_[d]) / cell_[d])), 0, dims_[d] - 1); };
  const int ncells = dims_[0] * dims_[1] * dims_[2];
  std::vector<int>& cell_of = gb.cell_of;
  std::vector<int>& cell_start = gb.cell_start;
  cell_of.resize(n_);
  cell_start.assign(ncells + 1, 0);
  for (int p = 0; p < n_; ++p) {
    cell_of[p] = (coord(qz_[p], 2) * dims_[1] + coord(qy_[p], 1)) * dims_[0] + coord(qx_[p], 0);
    ++cell_start[cell_of[p] + 1];
  }
  for (int c = 0; c < ncells; ++c) cell_start[c + 1] += cell_start[c];
  order_.resize(n_);
  std::vector<int>& fill = gb.fill;
  fill.assign(cell_start.begin(), cell_start.end() - 1);
  for (int p = 0; p < n_; ++p) order_[fill[cell_of[p]]++] = p;  // stable: ascending p in a cell
  // The half-space test is needed only where the ball crosses the plane: for |p - x_i| <= r_i,
  // (p - c).(x_i - c) >= |x_i - c| (|x_i - c| - r_i) and |p - c| <= |x_i - c| + r_i, so every
  // point of the ball passes the test of the kernel when |x_i - c| - r_i > 1e-9 (|x_i - c| + r_i);
  // checked with 1e-6 and r_i enlarged by 1e-3 (the kernel's y <= ymax rounds), far beyond rounding.
  plane_test_.assign(n_, 0);
  for (int i = 0; i < n_; ++i) {
    const double ri = 1.001 * r[i];
    plane_test_[i] = options_.half_space && !(qnorm_[i] - ri > 1e-6 * (qnorm_[i] + ri));
  }
  // The neighbour lists, once per shape: for each vertex, the runs of sorted points (one per row
  // of cells) that meet its ball of radius r_i; every apply() scans only these. A run may hold
  // points outside the ball (the kernel tests every distance), never miss one inside, so cell
  // indices may be rounded outwards: truncation instead of floor, clamped to the grid. Each
  // thread lists a contiguous range of vertices; the lists are joined in vertex order.
  const int nx = dims_[0], ny = dims_[1], nz = dims_[2];
  const double inv_cell[3] = {1.0 / cell_[0], 1.0 / cell_[1], 1.0 / cell_[2]};
  auto cell_index = [&](double v, int d) { return static_cast<int>((v - lo_[d]) * inv_cell[d]); };
  run_start_.assign(n_ + 1, 0);
  std::vector<std::vector<int>>& parts = gb.parts;
  parts.resize(omp_get_max_threads());
  for (std::vector<int>& part : parts) part.clear();
#pragma omp parallel
  {
    const int threads = omp_get_num_threads(), t = omp_get_thread_num();
    const int i_begin = static_cast<int>(static_cast<long>(n_) * t / threads);
    const int i_end = static_cast<int>(static_cast<long>(n_) * (t + 1) / threads);
    std::vector<int>& runs = parts[t];
    runs.reserve(static_cast<std::size_t>(i_end - i_begin) * 48);
    for (int i = i_begin; i < i_end; ++i) {
      const double xi = qx_[i], yi = qy_[i], zi = qz_[i];
      const double r2 = r[i] * r[i], ri = r[i];
      // Distance from v to the interval of cell c along axis d.
      auto gap = [&](double v, int d, int c) {
        const double l = lo_[d] + c * cell_[d], h = l + cell_[d];
        return v < l ? l - v : (v > h ? v - h : 0.0);
      };
      const std::size_t first = runs.size();
      const int z0 = std::max(0, cell_index(zi - ri, 2)), z1 = std::min(nz - 1, cell_index(zi + ri, 2));
      const int y0 = std::max(0, cell_index(yi - ri, 1)), y1 = std::min(ny - 1, cell_index(yi + ri, 1));
      for (int cz = z0; cz <= z1; ++cz) {
        const double gz = gap(zi, 2, cz);
        for (int cy = y0; cy <= y1; ++cy) {
          const double gy = gap(yi, 1, cy);
          const double rest = r2 - gz * gz - gy * gy;
          if (rest < 0) continue;
          // The cells of this row within the ball: one contiguous run of points.
          const double rx = std::sqrt(rest);
          const int x0 = std::max(0, cell_index(xi - rx, 0)), x1 = std::min(nx - 1, cell_index(xi + rx, 0));
          if (x0 > x1) continue;
          const int base = (cz * ny + cy) * nx;
          const int k0 = cell_start[base + x0], k1 = cell_start[base + x1 + 1];
          if (k0 == k1) continue;
          if (runs.size() > first && runs.back() == k0) {
            runs.back() = k1;  // continues the previous run
          } else {
            runs.push_back(k0);
            runs.push_back(k1);
          }
        }
      }
      run_start_[i + 1] = static_cast<int>(runs.size() - first);
    }
  }
  // Joined: vertex i's runs at [run_start_[i], run_start_[i + 1]).
  for (int i = 0; i < n_; ++i) run_start_[i + 1] += run_start_[i];
  // Copied (a few MB, a fraction of a percent of the applies), not moved: both buffers stay for
  // the next shape.
  runs_.clear();
  runs_.reserve(run_start_[n_]);
  for (const std::vector<int>& part : parts) runs_.insert(runs_.end(), part.begin(), part.end());
  run_shared_ = false;
}

// The reference form (run_sum_body): for every vertex i, the sum of eq. (13) over all points.
template <int Cols>
void BelkinLaplacian::apply_columns(const double* const* w, double* const* out, std::vector<double>& ws) const {
  // The fields in the points' (scan) order, so that a run reads contiguous memory.
  // Each column padded by kLanes zeros (the kernel reads whole blocks).
  const std::size_t stride = static_cast<std::size_t>(n_) + kLanes;
  ws.assign(static_cast<std::size_t>(Cols) * stride, 0.0);
  for (int col = 0; col < Cols; ++col)
    for (int k = 0; k < n_; ++k) ws[col * stride + k] = w[col][order_[k]];
  KernelInput in{};
  in.sx = point_array(0), in.sy = point_array(1), in.sz = point_array(2), in.sn = point_array(3);
  in.sl = point_array(4);
  for (int col = 0; col < 3; ++col) in.w[col] = ws.data() + (col < Cols ? col : 0) * stride;
  in.emax = max_exponent_;
  in.half_space = options_.half_space;
#pragma omp parallel for schedule(dynamic, 64) firstprivate(in)
  for (int i = 0; i < n_; ++i) {
    in.xi = qx_[i], in.yi = qy_[i], in.zi = qz_[i];
    in.margin = kPlaneTolerance * qnorm_[i];
    const double a = kernel_area_[i];
    in.inv4a = 1.0 / (4.0 * a);
    for (int col = 0; col < 3; ++col) in.wi[col] = w[col < Cols ? col : 0][i];
    double acc[3] = {0, 0, 0};
    const int r0 = run_shared_ ? 0 : run_start_[i], r1 = run_shared_ ? 2 : run_start_[i + 1];
    if constexpr (Cols == 1)
      run_sum1(in, runs_.data() + r0, (r1 - r0) / 2, acc);
    else
      run_sum3(in, runs_.data() + r0, (r1 - r0) / 2, acc);
    const double scale = 1.0 / (4.0 * M_PI * a * a);  // eq. (13) prefactor
    for (int col = 0; col < Cols; ++col) out[col][i] = scale * acc[col];
  }
}

// The grid form (grid_sum_body): w a scalar field (out[0]), or null for Lap x (out[0..2]).
void BelkinLaplacian::apply_grid(const double* w, double* const* out, std::vector<double>& buffer) const {
  // The field in the points' (scan) order, 64-byte aligned, padded by zeros.
  buffer.assign(w ? n_ + kLanes + 8 : 0, 0.0);
  double* ws = w ? aligned64(buffer.data()) : nullptr;
  for (int k = 0; w && k < n_; ++k) ws[k] = w[order_[k]];
  GridInput in = grid_input(point_array(0), point_array(1), point_array(2), point_array(3), point_array(4), ws,
                            max_exponent_);
  const GridKernels& kernels = grid_kernels();
  const double* weights = has_weights_ ? weights_.data.get() : nullptr;
#pragma omp parallel for schedule(dynamic, 64) firstprivate(in)
  for (int i = 0; i < n_; ++i) {
    set_vertex(in, qx_[i], qy_[i], qz_[i], qnorm_[i], kernel_area_[i], w ? w[i] : 0.0);
    double acc[3] = {0, 0, 0};
    const int* runs = runs_.data() + run_start_[i];
    const int nruns = (run_start_[i + 1] - run_start_[i]) / 2;
    if (weights && w)  // (with weights, Lap x was summed when they were stored: apply_to_positions)
      kernels.cached(in, runs, nruns, weights + weight_start_[i], acc);
    else
      kernels.k[w ? 0 : 1][plane_test_[i] ? 1 : 0](in, runs, nruns, acc);
    const double a = kernel_area_[i];
    const double scale = 1.0 / (4.0 * M_PI * a * a);  // eq. (13) prefactor
    for (int col = 0; col < (w ? 1 : 3); ++col) out[col][i] = scale * acc[col];
  }
}

namespace {
void check_field_size(Eigen::Index size, int n, const char* what) {
  if (size != n)
    throw Error("belkin_laplacian: field has " + std::to_string(size) + " " + what + ", mesh has " + std::to_string(n) +
                " vertices");
}
}  // namespace

Scalars BelkinLaplacian::apply(const Scalars& w) const {
  check_field_size(w.size(), n_, "values");
  Scalars out(n_);
  std::vector<double> buffer;
  const double* in[1] = {w.data()};
  double* res[1] = {out.data()};
  if (run_shared_)
    apply_columns<1>(in, res, buffer);
  else
    apply_grid(w.data(), res, buffer);
  return out;
}

void BelkinLaplacian::apply_into(const Scalars& w, Scalars& out) {
  check_field_size(w.size(), n_, "values");
  out.resize(n_);
  const double* in[1] = {w.data()};
  double* res[1] = {out.data()};
  if (run_shared_)
    apply_columns<1>(in, res, field_buffer_);
  else
    apply_grid(w.data(), res, field_buffer_);
}

Points BelkinLaplacian::apply(const Points& w) const {
  check_field_size(w.rows(), n_, "rows");
  // Column-major copies so that the inner loop over p reads contiguous memory.
  const Eigen::MatrixXd wc = w;
  Eigen::MatrixXd oc(n_, 3);
  std::vector<double> buffer;
  const double* in[3] = {wc.col(0).data(), wc.col(1).data(), wc.col(2).data()};
  double* res[3] = {oc.col(0).data(), oc.col(1).data(), oc.col(2).data()};
  if (run_shared_) {
    apply_columns<3>(in, res, buffer);
  } else {
    for (int col = 0; col < 3; ++col) apply_grid(in[col], res + col, buffer);
  }
  return oc;
}

void BelkinLaplacian::apply_into(const Points& w, Points& out) {
  check_field_size(w.rows(), n_, "rows");
  columns_in_ = w;
  columns_out_.resize(n_, 3);
  const double* in[3] = {columns_in_.col(0).data(), columns_in_.col(1).data(), columns_in_.col(2).data()};
  double* res[3] = {columns_out_.col(0).data(), columns_out_.col(1).data(), columns_out_.col(2).data()};
  if (run_shared_) {
    apply_columns<3>(in, res, field_buffer_);
  } else {
    for (int col = 0; col < 3; ++col) apply_grid(in[col], res + col, field_buffer_);
  }
  out = columns_out_;
}

Points BelkinLaplacian::apply_to_positions() const {
  if (run_shared_) {
    Points q(n_, 3);
    for (int p = 0; p < n_; ++p) q.row(p) = Eigen::RowVector3d(qx_[p], qy_[p], qz_[p]);
    return apply(q);
  }
  if (has_weights_) return lap_positions_;  // computed with the weights
  Eigen::MatrixXd oc(n_, 3);
  std::vector<double> buffer;
  double* res[3] = {oc.col(0).data(), oc.col(1).data(), oc.col(2).data()};
  apply_grid(nullptr, res, buffer);
  return oc;
}

void BelkinLaplacian::apply_to_positions_into(Points& out) {
  if (run_shared_) {
    positions_buffer_.resize(n_, 3);
    for (int p = 0; p < n_; ++p) positions_buffer_.row(p) = Eigen::RowVector3d(qx_[p], qy_[p], qz_[p]);
    apply_into(positions_buffer_, out);
    return;
  }
  if (has_weights_) {
    out = lap_positions_;  // computed with the weights
    return;
  }
  columns_out_.resize(n_, 3);
  double* res[3] = {columns_out_.col(0).data(), columns_out_.col(1).data(), columns_out_.col(2).data()};
  apply_grid(nullptr, res, field_buffer_);
  out = columns_out_;
}

Scalars belkin_laplacian(const Topology& topology, const Points& x, const MeshGeometry& geometry, const Scalars& w,
                         const BelkinOptions& options) {
  return BelkinLaplacian(topology, x, geometry, options).apply(w);
}
Points belkin_laplacian(const Topology& topology, const Points& x, const MeshGeometry& geometry, const Points& w,
                        const BelkinOptions& options) {
  return BelkinLaplacian(topology, x, geometry, options).apply(w);
}
Scalars belkin_laplacian(const Topology& topology, const Points& x, const MeshGeometry& geometry, const Scalars& w) {
  return belkin_laplacian(topology, x, geometry, w, BelkinOptions{});
}
Points belkin_laplacian(const Topology& topology, const Points& x, const MeshGeometry& geometry, const Points& w) {
  return belkin_laplacian(topology, x, geometry, w, BelkinOptions{});
}

std::unique_ptr<BendingMethod> BelkinMethod::create(const MethodOptions& options) {
  const MethodOptions r = resolve_method_options(info(), options);
  BelkinOptions o;
  o.neighbours = r.at("neighbours") == "all" ? BelkinOptions::Neighbours::all : BelkinOptions::Neighbours::grid;
  o.kernel_cutoff = option_real(r, "kernel_cutoff");
  return std::make_unique<BelkinMethod>(o);
}

MethodInfo BelkinMethod::info() {
  MethodInfo m{"D", "Belkin: heat-kernel Laplace-Beltrami operator in eq. (10), eq. (13)",
                {choice_option("neighbours", {"grid", "all"}, "grid",
                               "grid: the points within the kernel's cutoff radius, through a cell list; all: every pair"),
                 real_option("kernel_cutoff", 1e-300, 0.5, 1e-15,
                             "heat-kernel weights below this are dropped (neighbours=grid)")},
                {}, &BelkinMethod::create};
  m.capabilities.cost = std::string("O(N)");
  return m;
}

// Kept by the method instance and reused from call to call (method_workspace.hpp).
struct BelkinMethod::Workspace {
  MeshGeometry geometry;
  BelkinLaplacian laplacian;
  Points lap_x;
};

BelkinMethod::BelkinMethod(BelkinOptions options) : options_(options) {}
BelkinMethod::~BelkinMethod() = default;

void BelkinMethod::fields(const Topology& topology, const Points& x, BendingResult& out) const {
  const auto ws = workspace_.acquire();
  MeshGeometry& g = ws->geometry;
  MeshGeometry::compute(topology, x, g);
  BelkinLaplacian& lap = ws->laplacian;
  lap.prepare(topology, x, g, options_);
  // eq. (2) with eq. (13): Lap x = -2 H n.
  // The reference applies the operator to x itself (the grid form: to x - c, the same up to rounding).
  Points& lap_x = ws->lap_x;
  if (options_.neighbours == BelkinOptions::Neighbours::all)
    lap.apply_into(x, lap_x);
  else
    lap.apply_to_positions_into(lap_x);
  out.H.resize(topology.num_vertices());
  for (int i = 0; i < topology.num_vertices(); ++i) out.H[i] = -0.5 * lap_x.row(i).dot(g.normal_mwa.row(i));
  lap.apply_into(out.H, out.lapH);  // eq. (13) applied to H
  // The geometry's arrays change places with the result's (no copy; next call they are reused).
  out.normal.swap(g.normal_mwa);
  out.K.swap(g.gaussian_curvature);
  out.area.swap(g.mixed_area);
}

}  // namespace bendlab
