// The regular sums of the single layer (flow/bim/stokeslet_sums.hpp): the double kernel against
// the Stokeslet summed term by term, the single-precision one within its rounding.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "bendlab/core/types.hpp"
#include "bendlab/flow/bim/stokeslet_sums.hpp"

using namespace bendlab;

namespace {

struct Sources {
  std::vector<double> x, y, z, fx, fy, fz;
  explicit Sources(int n, unsigned seed = 5) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    for (auto* v : {&x, &y, &z, &fx, &fy, &fz}) v->resize(n);
    for (int k = 0; k < n; ++k) x[k] = u(rng), y[k] = u(rng), z[k] = u(rng), fx[k] = u(rng), fy[k] = u(rng), fz[k] = u(rng);
  }
};

// G(y_k, x) . F_k summed in order, in long double.
Vec3 plain(const Sources& s, int begin, int end, const Vec3& x) {
  long double u[3] = {0, 0, 0};
  for (int k = begin; k < end; ++k) {
    const long double d[3] = {s.x[k] - x[0], s.y[k] - x[1], s.z[k] - x[2]}, f[3] = {s.fx[k], s.fy[k], s.fz[k]};
    const long double r = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    const long double fd = f[0] * d[0] + f[1] * d[1] + f[2] * d[2];
    for (int c = 0; c < 3; ++c) u[c] += f[c] / r + d[c] * fd / (r * r * r);
  }
  return Vec3(double(u[0]), double(u[1]), double(u[2]));
}

}  // namespace

TEST(StokesletSums, RegularSumIsTheStokesletTermByTerm) {
  const Sources s(1037);  // not a multiple of any vector width: the remainder loop too
  for (const Vec3& x : {Vec3(2.5, 0.1, -0.3), Vec3(0.05, 0.02, 0.01), Vec3(-1.5, 1.5, 1.5)}) {
    for (const int n : {1, 7, 1037}) {
      double out[3];
      regular_sum(x[0], x[1], x[2], s.x.data(), s.y.data(), s.z.data(), s.fx.data(), s.fy.data(), s.fz.data(), n, out);
      const Vec3 expect = plain(s, 0, n, x);
      EXPECT_LT((Vec3(out[0], out[1], out[2]) - expect).norm(), 1e-12 * expect.norm()) << n << " " << x.transpose();
    }
  }
  double zero[3] = {1, 1, 1};
  regular_sum(0, 0, 0, s.x.data(), s.y.data(), s.z.data(), s.fx.data(), s.fy.data(), s.fz.data(), 0, zero);
  EXPECT_EQ(Vec3(zero[0], zero[1], zero[2]), Vec3::Zero());
}

TEST(StokesletSums, MixedSumsWithinSinglePrecisionAndPaddingAddsNothing) {
  // Two ranges about their own centres, each a whole number of blocks, the points stored relative
  // to the centre in float and the target's offset given, as the tree stores leaves and proxies.
  const int counts[2] = {3 * kMixedBlock, 5 * kMixedBlock};
  const Vec3 centres[2] = {Vec3(0.2, -0.1, 0.3), Vec3(-0.4, 0.5, 0.0)};
  const Sources s(counts[0] + counts[1], 9);
  std::vector<float> x, y, z, fx, fy, fz;
  for (int r = 0, k = 0; r < 2; ++r)
    for (int m = 0; m < counts[r]; ++m, ++k) {
      x.push_back(float(0.1 * s.x[k])), y.push_back(float(0.1 * s.y[k])), z.push_back(float(0.1 * s.z[k]));
      fx.push_back(float(s.fx[k])), fy.push_back(float(s.fy[k])), fz.push_back(float(s.fz[k]));
    }
  // The same sources in double (what the floats hold) for the expected value.
  Sources d(counts[0] + counts[1]);
  for (int r = 0, k = 0; r < 2; ++r)
    for (int m = 0; m < counts[r]; ++m, ++k) {
      d.x[k] = double(x[k]) + centres[r][0], d.y[k] = double(y[k]) + centres[r][1], d.z[k] = double(z[k]) + centres[r][2];
      d.fx[k] = fx[k], d.fy[k] = fy[k], d.fz[k] = fz[k];
    }
  const Vec3 target(1.7, -0.8, 0.9);
  MixedRange ranges[2];
  for (int r = 0, start = 0; r < 2; start += counts[r], ++r) {
    const Vec3 o = target - centres[r];
    ranges[r] = {start, counts[r], float(o[0]), float(o[1]), float(o[2])};
  }
  double out[3];
  mixed_sums(ranges, 2, x.data(), y.data(), z.data(), fx.data(), fy.data(), fz.data(), out);
  const Vec3 expect = plain(d, 0, counts[0] + counts[1], target);
  EXPECT_LT((Vec3(out[0], out[1], out[2]) - expect).norm(), 1e-6 * expect.norm());
  EXPECT_GT((Vec3(out[0], out[1], out[2]) - expect).norm(), 0.0);  // it is single precision
  // One more block of zero weights at the range's first point changes nothing, bit for bit.
  std::vector<float> px = x, py = y, pz = z, pfx = fx, pfy = fy, pfz = fz;
  for (int m = 0; m < kMixedBlock; ++m) {
    px.push_back(x[counts[0]]), py.push_back(y[counts[0]]), pz.push_back(z[counts[0]]);
    pfx.push_back(0.0f), pfy.push_back(0.0f), pfz.push_back(0.0f);
  }
  MixedRange padded[2] = {ranges[0], ranges[1]};
  padded[1].count += kMixedBlock;
  double out_padded[3];
  mixed_sums(padded, 2, px.data(), py.data(), pz.data(), pfx.data(), pfy.data(), pfz.data(), out_padded);
  for (int c = 0; c < 3; ++c) EXPECT_EQ(out_padded[c], out[c]);
}
