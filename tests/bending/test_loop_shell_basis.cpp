// Method S: shape functions of Loop patches (METHOD_S.md sections 1-2) and the quadrature rules.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

#include "bendlab/bending/loop_shell_basis.hpp"
#include "bendlab/core/types.hpp"

namespace bendlab::loop_shell {
namespace {

TEST(LoopShellBasis, BoxSplinesMatchTheTabulatedValues) {
  // METHOD_S.md section 1, at (v, w) = (0.2, 0.3), from an independent implementation.
  const double expected[12] = {.009375, .011458, .046992, .361225, .070950, .000800,
                               .216950, .258492, .002925, .000533, .018725, .001575};
  const auto b = box_splines(0.2, 0.3);
  for (int k = 0; k < 12; ++k) EXPECT_NEAR(b(kValue, k), expected[k], 6e-7) << "N" << k + 1;
}

TEST(LoopShellBasis, BoxSplinesPartitionOfUnityLinearPrecisionAndPositivity) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const auto& off = box_spline_offsets();
  for (int s = 0; s < 200; ++s) {
    double v = u(rng), w = u(rng);
    if (v + w > 1) v = 1 - v, w = 1 - w;
    const auto b = box_splines(v, w);
    EXPECT_NEAR(b.row(kValue).sum(), 1.0, 1e-14);
    for (int r = kDv; r <= kDww; ++r) EXPECT_NEAR(b.row(r).sum(), 0.0, 1e-13);
    double pv = 0, pw = 0, dvv = 0, dvw = 0, dwv = 0, dww = 0;
    for (int k = 0; k < 12; ++k) {
      EXPECT_GE(b(kValue, k), -1e-15);
      pv += b(kValue, k) * off[k].first, pw += b(kValue, k) * off[k].second;
      dvv += b(kDv, k) * off[k].first, dvw += b(kDw, k) * off[k].first;
      dwv += b(kDv, k) * off[k].second, dww += b(kDw, k) * off[k].second;
    }
    EXPECT_NEAR(pv, v, 1e-14);
    EXPECT_NEAR(pw, w, 1e-14);
    EXPECT_NEAR(dvv, 1.0, 1e-13);
    EXPECT_NEAR(dvw, 0.0, 1e-13);
    EXPECT_NEAR(dwv, 0.0, 1e-13);
    EXPECT_NEAR(dww, 1.0, 1e-13);
  }
}

TEST(LoopShellBasis, BoxSplinesCornerIsTheLoopLimitMask) {
  const auto b = box_splines(0.0, 0.0);
  const double mask[12] = {1, 1, 1, 6, 1, 0, 1, 1, 0, 0, 0, 0};
  for (int k = 0; k < 12; ++k) EXPECT_NEAR(b(kValue, k), mask[k] / 12.0, 1e-15);
}

// Derivatives of a basis against central differences of its values and first derivatives.
void expect_derivatives_match(int n, double v, double w) {
  const double h = 1e-5;
  const PatchBasis b = patch_basis(n, v, w);
  const PatchBasis bvp = patch_basis(n, v + h, w), bvm = patch_basis(n, v - h, w);
  const PatchBasis bwp = patch_basis(n, v, w + h), bwm = patch_basis(n, v, w - h);
  const double scale = b.cwiseAbs().maxCoeff();
  for (Eigen::Index i = 0; i < b.cols(); ++i) {
    EXPECT_NEAR(b(kDv, i), (bvp(kValue, i) - bvm(kValue, i)) / (2 * h), 1e-7 * scale);
    EXPECT_NEAR(b(kDw, i), (bwp(kValue, i) - bwm(kValue, i)) / (2 * h), 1e-7 * scale);
    EXPECT_NEAR(b(kDvv, i), (bvp(kDv, i) - bvm(kDv, i)) / (2 * h), 1e-6 * scale);
    EXPECT_NEAR(b(kDvw, i), (bwp(kDv, i) - bwm(kDv, i)) / (2 * h), 1e-6 * scale);
    EXPECT_NEAR(b(kDww, i), (bwp(kDw, i) - bwm(kDw, i)) / (2 * h), 1e-6 * scale);
  }
}

TEST(LoopShellBasis, DerivativesMatchFiniteDifferences) {
  for (int n : {3, 4, 5, 6, 7, 8}) {
    // Interior points of the three sub-triangles at levels 0, 1 and 2 (away from their borders).
    for (auto [v, w] : {std::pair{0.6, 0.15}, {0.15, 0.6}, {0.3, 0.35}, {0.3, 0.05}, {0.1, 0.17}, {0.05, 0.07}})
      expect_derivatives_match(n, v, w);
  }
}

TEST(LoopShellBasis, SubdivisionReproducesTheBoxSplinesForValenceSix) {
  for (auto [v, w] : {std::pair{0.6, 0.15}, {0.15, 0.6}, {0.3, 0.35}, {0.01, 0.02}, {0.2, 0.1}, {3e-3, 1e-3}}) {
    const PatchBasis a = patch_basis(6, v, w), b = patch_basis_by_subdivision(6, v, w);
    EXPECT_LT((a - b).cwiseAbs().maxCoeff(), 1e-10 * a.cwiseAbs().maxCoeff()) << v << " " << w;
  }
}

TEST(LoopShellBasis, IrregularPartitionOfUnityAndLinearPrecision) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int n : {3, 4, 5, 7, 8, 9}) {
    // Control values of an affine function of random control positions: the patch reproduces it.
    Eigen::MatrixXd p = Eigen::MatrixXd::Random(n + 6, 3);
    const Vec3 c(0.3, -1.2, 0.7);
    const Eigen::VectorXd g = p * c + Eigen::VectorXd::Constant(n + 6, 0.4);
    for (int s = 0; s < 50; ++s) {
      double v = u(rng), w = u(rng);
      if (v + w > 1) v = 1 - v, w = 1 - w;
      if (v + w < 1e-6) continue;
      const PatchBasis b = patch_basis(n, v, w);
      EXPECT_NEAR(b.row(kValue).sum(), 1.0, 1e-13);
      for (int r = kDv; r <= kDww; ++r) EXPECT_NEAR(b.row(r).sum(), 0.0, 1e-9 * b.row(r).cwiseAbs().sum());
      const Eigen::Matrix<double, 6, 3> x = b * p;
      const Eigen::Matrix<double, 6, 1> gx = b * g;
      EXPECT_NEAR(gx(kValue), x.row(kValue).dot(c) + 0.4, 1e-12);
      for (int r = kDv; r <= kDww; ++r) EXPECT_NEAR(gx(r), x.row(r).dot(c), 1e-9 * (1 + std::abs(gx(r))));
    }
  }
}

TEST(LoopShellBasis, PatchTendsToTheLimitMaskAtTheExtraordinaryVertex) {
  for (int n : {3, 4, 5, 7, 8}) {
    const double chi = limit_ring_weight(n);
    const PatchBasis b = patch_basis(n, 1e-10, 1e-10);
    EXPECT_NEAR(b(kValue, 0), 1.0 - n * chi, 1e-8) << n;
    for (int i = 1; i <= n; ++i) EXPECT_NEAR(b(kValue, i), chi, 1e-8) << n;
    for (int i = n + 1; i < n + 6; ++i) EXPECT_NEAR(b(kValue, i), 0.0, 1e-8) << n;
  }
  EXPECT_NEAR(limit_ring_weight(6), 1.0 / 12.0, 1e-16);
  EXPECT_NEAR(loop_beta(6), 1.0 / 16.0, 1e-16);
  EXPECT_THROW(patch_basis(5, 0.0, 0.0), Error);
}

TEST(LoopShellBasis, SubdivisionMatrixRowsSumToOne) {
  for (int n : {3, 5, 6, 7}) {
    const Eigen::MatrixXd a = subdivision_matrix(n);
    ASSERT_EQ(a.rows(), n + 12);
    ASSERT_EQ(a.cols(), n + 6);
    for (Eigen::Index r = 0; r < a.rows(); ++r) EXPECT_NEAR(a.row(r).sum(), 1.0, 1e-15) << r;
    // The subdominant eigenvalue pair 3/8 + cos(2 pi / N) / 4 of A (METHOD_S.md section 2).
    const Eigen::VectorXcd ev = Eigen::MatrixXd(a.topRows(n + 6)).eigenvalues();
    const double l1 = 3.0 / 8.0 + std::cos(2.0 * std::numbers::pi / n) / 4.0;
    int found = 0;
    for (Eigen::Index k = 0; k < ev.size(); ++k) found += std::abs(ev[k] - l1) < 1e-6;
    EXPECT_GE(found, 2) << n;
  }
}

TEST(LoopShellBasis, DunavantRulesIntegratePolynomialsExactly) {
  // int over the (v, w) triangle of v^a w^b = a! b! / (a + b + 2)!.
  auto fact = [](int k) { double r = 1; for (int i = 2; i <= k; ++i) r *= i; return r; };
  for (auto [points, degree] : {std::pair{1, 1}, {3, 2}, {6, 4}, {7, 5}, {12, 6}}) {
    const TriangleRule r = dunavant_rule(points);
    ASSERT_EQ(r.size(), points);
    for (int a = 0; a <= degree; ++a)
      for (int b = 0; a + b <= degree; ++b) {
        double q = 0;
        for (int k = 0; k < r.size(); ++k) q += 0.5 * r.weight[k] * std::pow(r.v[k], a) * std::pow(r.w[k], b);
        EXPECT_NEAR(q, fact(a) * fact(b) / fact(a + b + 2), 1e-14) << points << " " << a << " " << b;
      }
  }
  EXPECT_THROW(dunavant_rule(4), Error);
}

}  // namespace
}  // namespace bendlab::loop_shell
