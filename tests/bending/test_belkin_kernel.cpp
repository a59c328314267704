// The sums of Belkin's heat kernel for one vertex (bending/belkin_kernel.hpp): the exponentials
// against the standard library, and each kernel against the same sum written as a plain loop.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "bendlab/bending/belkin_kernel.hpp"

using namespace bendlab::belkin_kernel;

namespace {

// Points in scan order around the origin (the volume centroid of the operator), their norms and
// lumped areas, each array padded by zeros past its end as the kernels require.
struct Cloud {
  int n;
  std::vector<double> x, y, z, norm, lump, w;
  explicit Cloud(int count, unsigned seed = 7) : n(count) {
    const std::size_t size = static_cast<std::size_t>(n) + kLanes + 8;
    for (auto* v : {&x, &y, &z, &norm, &lump, &w}) v->assign(size, 0.0);
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> u(-1.0, 1.0), a(0.5e-3, 2e-3);
    for (int k = 0; k < n; ++k) {
      x[k] = u(rng), y[k] = u(rng), z[k] = u(rng);
      norm[k] = std::sqrt(x[k] * x[k] + y[k] * y[k] + z[k] * z[k]);
      lump[k] = a(rng);
      w[k] = std::sin(3 * x[k]) + y[k] * z[k];
    }
  }
};

// The runs a vertex scans: three stretches of the cloud (a gap between them), as a cell list gives.
std::vector<int> some_runs(int n) { return {0, n / 4, n / 3, (2 * n) / 3, (3 * n) / 4, n}; }

// Sum over the runs of lump_p kernel(p) (w_p - w_i), the kernel and the kept terms as the caller says.
template <class Keep, class Kernel>
double plain_sum(const Cloud& c, const std::vector<int>& runs, int field, int i, Keep keep, Kernel kernel) {
  double s = 0;
  for (std::size_t r = 0; r < runs.size(); r += 2)
    for (int k = runs[r]; k < runs[r + 1]; ++k) {
      if (!keep(k)) continue;
      const double diff = field < 0 ? c.w[k] - c.w[i] : (field == 0 ? c.x[k] - c.x[i] : field == 1 ? c.y[k] - c.y[i] : c.z[k] - c.z[i]);
      s += c.lump[k] * kernel(k) * diff;
    }
  return s;
}

double dist2(const Cloud& c, int k, int i) {
  const double dx = c.x[k] - c.x[i], dy = c.y[k] - c.y[i], dz = c.z[k] - c.z[i];
  return dx * dx + dy * dy + dz * dz;
}

bool above(const Cloud& c, int k, int i) {
  return c.x[k] * c.x[i] + c.y[k] * c.y[i] + c.z[k] * c.z[i] > kPlaneTolerance * c.norm[i] * c.norm[k];
}

}  // namespace

TEST(BelkinKernel, ExpNegWithinAFewUlpOfStdExp) {
  double worst = 0;
  for (int k = 0; k <= 800000; ++k) {
    const double e = 80.0 * k / 800000;
    worst = std::max(worst, std::abs(exp_neg(e) - std::exp(-e)) / std::exp(-e));
  }
  EXPECT_LT(worst, 4 * 2.2e-16);
  EXPECT_EQ(exp_neg(0.0), 1.0);
}

TEST(BelkinKernel, Exp2NegWithin2p3e14OfStdExp2) {
  // The bound belkin_kernel.hpp states (measured against exp2l on 2e7 points of [0, 116]).
  double worst = 0;
  for (int k = 0; k <= 1160000; ++k) {
    const double y = 116.0 * k / 1160000;
    worst = std::max(worst, std::abs(exp2_neg(y) - std::exp2(-y)) / std::exp2(-y));
  }
  EXPECT_LT(worst, 2.3e-14);
}

TEST(BelkinKernel, ReferenceSumsArePlainLoops) {
  const Cloud c(1000);
  const std::vector<int> runs = some_runs(c.n);
  const int nruns = static_cast<int>(runs.size()) / 2;
  for (const bool half_space : {true, false}) {
    for (const int i : {3, 250, 777}) {
      const double a = 1.5e-2;  // a_i: the kernel's reach, about sqrt(4 a 80) = 2.2
      KernelInput in{};
      in.sx = c.x.data(), in.sy = c.y.data(), in.sz = c.z.data(), in.sn = c.norm.data(), in.sl = c.lump.data();
      in.w[0] = c.w.data(), in.w[1] = c.x.data(), in.w[2] = c.y.data();
      in.xi = c.x[i], in.yi = c.y[i], in.zi = c.z[i];
      in.margin = kPlaneTolerance * c.norm[i];
      in.inv4a = 1.0 / (4 * a);
      in.emax = kMaxExponent;
      in.wi[0] = c.w[i], in.wi[1] = c.x[i], in.wi[2] = c.y[i];
      in.half_space = half_space;
      auto keep = [&](int k) { return dist2(c, k, i) / (4 * a) <= kMaxExponent && (!half_space || above(c, k, i)); };
      auto kernel = [&](int k) { return std::exp(-dist2(c, k, i) / (4 * a)); };
      double one[1] = {0}, three[3] = {0, 0, 0};
      run_sum1(in, runs.data(), nruns, one);
      run_sum3(in, runs.data(), nruns, three);
      const double expect_w = plain_sum(c, runs, -1, i, keep, kernel);
      const double expect_x = plain_sum(c, runs, 0, i, keep, kernel);
      EXPECT_NEAR(one[0], expect_w, 1e-13 * std::abs(expect_w)) << half_space << " " << i;
      EXPECT_NEAR(three[0], one[0], 1e-15 * std::abs(one[0]));  // the same terms in the same order
      EXPECT_NEAR(three[1], expect_x, 1e-13 * std::abs(expect_x));
    }
  }
}

TEST(BelkinKernel, GridSumsArePlainLoops) {
  const Cloud c(1000, 11);
  const std::vector<int> runs = some_runs(c.n);
  const int nruns = static_cast<int>(runs.size()) / 2;
  const GridKernels& kernels = grid_kernels();
  ASSERT_TRUE(kernels.lanes == 4 || kernels.lanes == 8);
  const double max_exponent = -std::log(1e-15);  // the default kernel_cutoff
  std::vector<double> weights(c.n + 8 * nruns + 8);
  for (const int plane : {0, 1}) {
    for (const int i : {5, 400, 901}) {
      const double a = 8e-3;
      GridInput in = grid_input(c.x.data(), c.y.data(), c.z.data(), c.norm.data(), c.lump.data(), c.w.data(),
                                max_exponent);
      set_vertex(in, c.x[i], c.y[i], c.z[i], c.norm[i], a, c.w[i]);
      const double scale = kLog2e / (4 * a);
      auto keep = [&](int k) {
        return dist2(c, k, i) * scale <= max_exponent * kLog2e && (!plane || above(c, k, i));
      };
      auto kernel = [&](int k) { return std::exp2(-dist2(c, k, i) * scale); };
      double scalar[3] = {0, 0, 0}, positions[3] = {0, 0, 0}, stored[3] = {0, 0, 0}, cached[3] = {0, 0, 0};
      kernels.k[0][plane](in, runs.data(), nruns, scalar);
      kernels.k[1][plane](in, runs.data(), nruns, positions);
      kernels.weights[plane](in, runs.data(), nruns, weights.data(), stored);
      kernels.cached(in, runs.data(), nruns, weights.data(), cached);
      const double expect_w = plain_sum(c, runs, -1, i, keep, kernel);
      EXPECT_NEAR(scalar[0], expect_w, 1e-12 * std::abs(expect_w)) << plane << " " << i;
      for (int d = 0; d < 3; ++d) {
        const double expect = plain_sum(c, runs, d, i, keep, kernel);
        EXPECT_NEAR(positions[d], expect, 1e-12 * std::abs(expect)) << plane << " " << i << " " << d;
        EXPECT_NEAR(stored[d], positions[d], 1e-15 * std::abs(positions[d]));  // storing changes no sum
      }
      // The stored weights give the scalar field's sum again without an exponential.
      EXPECT_NEAR(cached[0], scalar[0], 1e-15 * std::abs(scalar[0]));
    }
  }
}

TEST(BelkinKernel, PointsPastARunsEndWeighNothing) {
  // The kernels read whole blocks: what lies after a run's end (here a point right at x_i with a
  // large field value) must not enter the sum.
  Cloud c(64, 3);
  const int i = 10;
  c.x[40] = c.x[i], c.y[40] = c.y[i], c.z[40] = c.z[i], c.w[40] = 1e6;
  const std::vector<int> runs = {0, 37};  // 37: not a multiple of any block width
  const double max_exponent = kMaxExponent;
  GridInput in = grid_input(c.x.data(), c.y.data(), c.z.data(), c.norm.data(), c.lump.data(), c.w.data(),
                            max_exponent);
  set_vertex(in, c.x[i], c.y[i], c.z[i], c.norm[i], 1.0, c.w[i]);
  double s[3] = {0, 0, 0};
  grid_kernels().k[0][0](in, runs.data(), 1, s);
  auto keep = [](int) { return true; };
  auto kernel = [&](int k) { return std::exp2(-dist2(c, k, i) * kLog2e / 4.0); };
  const double expect = plain_sum(c, runs, -1, i, keep, kernel);
  EXPECT_NEAR(s[0], expect, 1e-12 * std::abs(expect));
}
