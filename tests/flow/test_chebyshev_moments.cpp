// The tree quadrature's Chebyshev moments: the four-points-per-vector kernel against the point by
// point reference, and exact values the definition fixes.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "bendlab/flow/bim/chebyshev_moments.hpp"

namespace bendlab {
namespace {

struct Sources {
  std::vector<double> x, y, z, fx, fy, fz;
};

Sources random_sources(int count, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Sources s;
  for (int k = 0; k < count; ++k) {
    s.x.push_back(0.3 + 0.2 * u(rng));
    s.y.push_back(-0.1 + 0.1 * u(rng));
    s.z.push_back(0.05 * u(rng));
    s.fx.push_back(u(rng));
    s.fy.push_back(u(rng));
    s.fz.push_back(u(rng));
  }
  return s;
}

// The sources' box (half widths 0.2, 0.1, 0.05) scaled to [-1, 1]^3, rotated about z and shrunk by
// 1 / 1.4 so that the rotated box stays inside: s = S (y - centre) in [-1, 1]^3, |T_n(s)| <= 1.
constexpr double kShrink = 1 / 1.4;
const double kS[9] = {0.6 * 5 * kShrink, 0.8 * 5 * kShrink, 0, -0.8 * 10 * kShrink, 0.6 * 10 * kShrink, 0,
                      0, 0, 20};  // column-major
const double kCentre[3] = {0.3, -0.1, 0.0};

TEST(ChebyshevMoments, VectorKernelEqualsReference) {
  for (int q = 0; q <= 8; ++q)
    for (const int count : {0, 1, 3, 4, 5, 17, 224, 230}) {
      const Sources s = random_sources(count, 11u + q);
      const int nm = chebyshev_moment_count(q);
      std::vector<double> ref(3 * nm, 0.25), fast(3 * nm, 0.25);  // both add to what is there
      chebyshev_moments_reference(kS, kCentre, q, s.x.data(), s.y.data(), s.z.data(), s.fx.data(), s.fy.data(),
                                  s.fz.data(), count, ref.data(), ref.data() + nm, ref.data() + 2 * nm);
      chebyshev_moments(kS, kCentre, q, s.x.data(), s.y.data(), s.z.data(), s.fx.data(), s.fy.data(), s.fz.data(),
                        count, fast.data(), fast.data() + nm, fast.data() + 2 * nm);
      // Each term is at most max|F| max|T|^3 <= 1 (|T| <= 1 in the box): the two differ by the
      // rounding of a sum of `count` such terms in another order (and of the products).
      for (int m = 0; m < 3 * nm; ++m)
        EXPECT_NEAR(fast[m], ref[m], 1e-15 * (count + 1) * 8) << "q " << q << ", count " << count << ", moment " << m;
    }
}

TEST(ChebyshevMoments, PointAtTheCentreGivesTheChebyshevValuesAtZero) {
  // T_n(0) = cos(n pi / 2): 1, 0, -1, 0, 1, ...; one source at the centre with weight (1, 2, 3).
  const int q = 6, nm = chebyshev_moment_count(q);
  const double x = kCentre[0], y = kCentre[1], z = kCentre[2], fx = 1, fy = 2, fz = 3;
  std::vector<double> m(3 * nm, 0.0);
  chebyshev_moments(kS, kCentre, q, &x, &y, &z, &fx, &fy, &fz, 1, m.data(), m.data() + nm, m.data() + 2 * nm);
  auto t0 = [](int n) { return n % 2 ? 0.0 : (n % 4 ? -1.0 : 1.0); };
  int beta = 0;
  for (int a = 0; a <= q; ++a)
    for (int b = 0; a + b <= q; ++b)
      for (int c = 0; a + b + c <= q; ++c, ++beta) {
        const double t = t0(a) * t0(b) * t0(c);
        EXPECT_EQ(m[beta], t * fx) << a << b << c;
        EXPECT_EQ(m[nm + beta], t * fy) << a << b << c;
        EXPECT_EQ(m[2 * nm + beta], t * fz) << a << b << c;
      }
  EXPECT_EQ(beta, nm);
}

TEST(ChebyshevMoments, DegreeOneMomentsAreWeightedCoordinates) {
  // T_0 = 1, T_1(s) = s: beta = (0,0,0) is the total weight, (0,0,1), (0,1,0), (1,0,0) its first
  // moments in the box coordinates s = S (y - centre).
  const Sources s = random_sources(37, 5);
  const int nm = chebyshev_moment_count(1);
  std::vector<double> m(3 * nm, 0.0);
  chebyshev_moments(kS, kCentre, 1, s.x.data(), s.y.data(), s.z.data(), s.fx.data(), s.fy.data(), s.fz.data(), 37,
                    m.data(), m.data() + nm, m.data() + 2 * nm);
  double total = 0, first[3] = {0, 0, 0};
  for (int k = 0; k < 37; ++k) {
    const double r[3] = {s.x[k] - kCentre[0], s.y[k] - kCentre[1], s.z[k] - kCentre[2]};
    total += s.fy[k];
    for (int d = 0; d < 3; ++d) first[d] += (kS[d] * r[0] + kS[3 + d] * r[1] + kS[6 + d] * r[2]) * s.fy[k];
  }
  // Order of tree_basis_: (0,0,0), (0,0,1), (0,1,0), (1,0,0).
  EXPECT_NEAR(m[nm + 0], total, 1e-13);
  EXPECT_NEAR(m[nm + 1], first[2], 1e-12);
  EXPECT_NEAR(m[nm + 2], first[1], 1e-12);
  EXPECT_NEAR(m[nm + 3], first[0], 1e-12);
}

}  // namespace
}  // namespace bendlab
