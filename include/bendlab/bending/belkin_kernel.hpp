#pragma once
// The sums of Belkin's heat-kernel operator, eq. (13), for one vertex at a time: the innermost
// loops of belkin.hpp's BelkinLaplacian, which decides what each vertex scans (belkin_grid.cpp:
// the cell list; belkin_reference.cpp: every point) and scales the sums. What the code does not
// show:
// - the kernels (belkin_kernel.cpp) are compiled three times, for AVX-512, AVX2+FMA and baseline
//   x86-64 (target_clones), and the processor picks one at load time; that file is built with
//   -fno-math-errno -ffp-contract=fast (CMakeLists.txt), so its sums fuse multiplies and adds and
//   differ in the last bits from the same expressions compiled elsewhere;
// - they read whole blocks of points, branch-free: every point array (and field in scan order)
//   must be padded past its end, by kLanes entries for the reference kernels and by one block of
//   the grid kernels' width for the grid ones, with finite values;
// - the lanes of a block are summed once per vertex, so a vertex's sum depends on how its points
//   fall into blocks: the same runs give the same numbers, a different scan order different
//   rounding.
#include <algorithm>
#include <bit>
#include <cstddef>
#include <cstdint>

namespace bendlab::belkin_kernel {

inline constexpr double kLog2e = 1.4426950408889634074;
// Terms with |p - x_i|^2 / (4 a_i) above this are skipped; see the bound in belkin.hpp.
inline constexpr double kMaxExponent = 80.0;
// A point p counts as above the plane of x_i when (p - c).(x_i - c) > kPlaneTolerance |p - c| |x_i - c|.
// Symmetric meshes put nodes exactly on the plane (the rim of a red blood cell for a node at a
// dimple centre); without the margin, rounding in c would decide whether those nodes count, so
// the result would change under a rotation or a scaling of the shape. Such nodes are left out, as
// the strict inequality of the rule says for points on the plane.
inline constexpr double kPlaneTolerance = 1e-9;
// The reference kernels' block: points summed side by side (and the padding they need).
inline constexpr int kLanes = 16;

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

// The kernels' input: the point arrays and a field in scan order (w, or null), ...
inline GridInput grid_input(const double* sx, const double* sy, const double* sz, const double* sn, const double* sl,
                     const double* w, double max_exponent) {
  GridInput in{};
  in.sx = sx, in.sy = sy, in.sz = sz, in.sn = sn, in.sl = sl, in.w = w;
  in.ymax = max_exponent * kLog2e;
  return in;
}
// ... and vertex i's part: its centred position, |x_i - c|, a_i and the field there.
inline void set_vertex(GridInput& in, double x, double y, double z, double norm, double a, double wi) {
  in.xi = x, in.yi = y, in.zi = z;
  in.margin = kPlaneTolerance * norm;
  in.scale = kLog2e / (4.0 * a);
  in.wi = wi;
}

/// The reference form's sums (run_sum_body in belkin_kernel.cpp) for one field (run_sum1: in.w[0])
/// or three (run_sum3), over the runs [runs[2r], runs[2r + 1]), r < nruns, added to acc.
void run_sum1(const KernelInput& in, const int* runs, int nruns, double* acc);
void run_sum3(const KernelInput& in, const int* runs, int nruns, double* acc);

/// The grid form's kernels: a scalar field or Lap x (k), the same storing each lane's weight in
/// scan order (weights), and a scalar field from stored weights (cached).
using GridKernel = void (*)(const GridInput&, const int*, int, double*);
using WeightKernel = void (*)(const GridInput&, const int*, int, double*, double*);
using CachedKernel = void (*)(const GridInput&, const int*, int, const double*, double*);
// k[field][plane]: field 0 scalar, 1 positions; weights[plane]; cached (scalar); the block width
// (lanes) of the processor's widest vectors.
struct GridKernels {
  GridKernel k[2][2];
  WeightKernel weights[2];
  CachedKernel cached;
  int lanes;
};
/// The kernels for this processor: blocks of 8 lanes where it has AVX-512, else of 4.
const GridKernels& grid_kernels();

// A 64-byte aligned position in a buffer of doubles with 8 spare entries at its start.
inline double* aligned64(double* p) {
  return p + (64 - reinterpret_cast<std::uintptr_t>(p) % 64) % 64 / sizeof(double);
}
inline const double* aligned64(const double* p) { return aligned64(const_cast<double*>(p)); }

}  // namespace bendlab::belkin_kernel
