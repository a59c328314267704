#include <gtest/gtest.h>

#include <cmath>

#include "bendlab/analysis/convergence.hpp"

using namespace bendlab;

namespace {
const std::vector<double> kH = {0.2, 0.1, 0.05, 0.025, 0.0125};

std::vector<double> power_law(double c, double p, const std::vector<double>& h = kH) {
  std::vector<double> e;
  for (double x : h) e.push_back(c * std::pow(x, p));
  return e;
}
}  // namespace

TEST(Convergence, SlopeRecoversThePowerOfAPowerLaw) {
  for (double p : {-2.0, -1.0, 0.0, 0.5, 1.0, 2.0, 3.0}) {
    EXPECT_NEAR(loglog_slope(kH, power_law(3.7, p)), -p, 1e-12) << p;
    // Unequal spacing and any order of the points give the same slope.
    const std::vector<double> h = {0.013, 0.3, 0.07};
    EXPECT_NEAR(loglog_slope(h, power_law(0.2, p, h)), -p, 1e-12) << p;
  }
}

TEST(Convergence, SlopeIsNaNWithoutUsableData) {
  EXPECT_TRUE(std::isnan(loglog_slope({0.1}, {1.0})));
  EXPECT_TRUE(std::isnan(loglog_slope({0.1, 0.1}, {1.0, 2.0})));
  EXPECT_TRUE(std::isnan(loglog_slope({0.1, 0.05}, {1.0, 0.0})));
  EXPECT_TRUE(std::isnan(loglog_slope({0.1, 0.05}, {1.0, NAN})));
  EXPECT_TRUE(std::isnan(loglog_slope({0.1, 0.05}, {1.0})));
}

TEST(Convergence, ClassifiesPowerLaws) {
  EXPECT_EQ(classify_convergence(kH, power_law(1, 2)).trend, Trend::ToZero);
  EXPECT_EQ(classify_convergence(kH, power_law(1, 1)).trend, Trend::ToZero);
  EXPECT_EQ(classify_convergence(kH, power_law(1, 0.6)).trend, Trend::ToZero);
  EXPECT_EQ(classify_convergence(kH, power_law(1, 0)).trend, Trend::Systematic);
  EXPECT_EQ(classify_convergence(kH, power_law(1, 0.3)).trend, Trend::Systematic);
  EXPECT_EQ(classify_convergence(kH, power_law(1, -1)).trend, Trend::Diverges);
  EXPECT_EQ(classify_convergence(kH, power_law(1, -2)).trend, Trend::Diverges);
  const TrendFit f = classify_convergence(kH, power_law(2, 2));
  EXPECT_EQ(f.points, 5);
  EXPECT_NEAR(f.slope_all, -2, 1e-12);
  EXPECT_NEAR(f.slope_tail, -2, 1e-12);
  EXPECT_NEAR(f.slope_last, -2, 1e-12);
}

TEST(Convergence, ClassifiesFromTheFinestMeshes) {
  // Converges as h^2, then levels off at 1e-3: a systematic error.
  std::vector<double> e;
  for (double h : kH) e.push_back(h * h + 1e-3);
  EXPECT_EQ(classify_convergence(kH, e).trend, Trend::Systematic);
  // Decreases first, then grows on the two finest meshes (the paper's Method E, Lap H): diverges.
  EXPECT_EQ(classify_convergence(kH, {1.0, 0.3, 0.1, 0.2, 0.4}).trend, Trend::Diverges);
  // Grows first, then converges fast on the finest three: to zero.
  EXPECT_EQ(classify_convergence(kH, {0.1, 0.5, 0.2, 0.05, 0.0125}).trend, Trend::ToZero);
  // Fast on the tail but stalling on the last refinement: systematic.
  EXPECT_EQ(classify_convergence(kH, {1.0, 0.25, 0.0625, 0.05, 0.045}).trend, Trend::Systematic);
  // Order of the points does not matter.
  EXPECT_EQ(classify_convergence({0.0125, 0.2, 0.05, 0.1, 0.025}, {0.4, 1.0, 0.1, 0.3, 0.2}).trend,
            Trend::Diverges);
}

TEST(Convergence, ExactAndUndeterminedSeries) {
  EXPECT_EQ(classify_convergence(kH, {1e-3, 0, 0, 0, 0}).trend, Trend::ToZero);
  EXPECT_EQ(classify_convergence({0.1}, {0.5}).trend, Trend::Undetermined);
  EXPECT_EQ(classify_convergence({0.1, 0.05}, {NAN, NAN}).trend, Trend::Undetermined);
  EXPECT_EQ(symbol(Trend::ToZero), "●");
  EXPECT_EQ(symbol(Trend::Systematic), "○");
  EXPECT_EQ(symbol(Trend::Diverges), "■");
}

TEST(Convergence, FitRatesGroupsRows) {
  std::vector<ErrorRow> rows;
  for (double h : kH) {
    rows.push_back({"mt1", 0, h, "C", "H", 2 * h * h, h * h});
    rows.push_back({"mt1", 0, h, "C", "lapH", 1 / h, 1.0});
    rows.push_back({"octa", 0, h, "C", "H", 1.0, 1.0});
  }
  const auto fits = fit_rates(rows, {"mt1"});
  ASSERT_EQ(fits.size(), 4u);
  EXPECT_EQ(fits[0].quantity, "H");
  EXPECT_EQ(fits[0].measure, "max");
  EXPECT_NEAR(fits[0].fit.slope_all, -2, 1e-12);
  EXPECT_EQ(fits[0].fit.trend, Trend::ToZero);
  EXPECT_EQ(fits[2].quantity, "lapH");
  EXPECT_EQ(fits[2].fit.trend, Trend::Diverges);
  EXPECT_EQ(fits[3].fit.trend, Trend::Systematic);
  EXPECT_EQ(fits[0].h.front(), 0.2);  // by decreasing h
}

TEST(Convergence, InterpolationIsExactForPowerLaws) {
  const std::vector<double> h = {0.1, 0.05, 0.025};
  EXPECT_NEAR(interpolate_loglog(h, power_law(3, 2, h), 0.07), 3 * 0.07 * 0.07, 1e-14);
  // Outside the range: extrapolated from the two nearest points.
  EXPECT_NEAR(interpolate_loglog(h, power_law(3, -1, h), 0.01), 300, 1e-9);
  EXPECT_NEAR(interpolate_loglog(h, power_law(3, 1, h), 0.2), 0.6, 1e-14);
  EXPECT_TRUE(std::isnan(interpolate_loglog({0.1}, {1.0}, 0.1)));
}

TEST(Convergence, InhomogeneousMeshAgainstHomogeneousReference) {
  std::vector<ErrorRow> rows;
  for (double h : {0.1, 0.05, 0.025}) {
    rows.push_back({"mt2", 0, h, "D", "H", h, h * h});
    rows.push_back({"mt2", 0, h, "C", "H", h, h * h});
    rows.push_back({"mt2", 0, h, "E", "H", h, h * h});
  }
  const double hr = 0.04;
  rows.push_back({"rivara-mt2", 3848, hr, "D", "H", 1.5 * hr, 1.5 * hr * hr});  // within the factor
  rows.push_back({"rivara-mt2", 3848, hr, "C", "H", 10 * hr, 10 * hr * hr});    // both worse
  rows.push_back({"rivara-mt2", 3848, hr, "E", "H", 3 * hr, hr * hr});          // only the maximum
  const auto checks = compare_inhomogeneous(rows, "rivara-mt2", "mt2");
  ASSERT_EQ(checks.size(), 3u);
  EXPECT_NEAR(checks[0].ratio_max, 1.5, 1e-12);
  EXPECT_NEAR(checks[0].ratio_avg, 1.5, 1e-12);
  EXPECT_EQ(checks[0].trouble, Trouble::None);
  EXPECT_EQ(checks[1].trouble, Trouble::Severe);
  EXPECT_NEAR(checks[1].ratio_avg, 10, 1e-12);
  EXPECT_EQ(checks[2].trouble, Trouble::MaxOnly);
  EXPECT_EQ(checks[2].origin, "mt2");
}
