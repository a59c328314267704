#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "bendlab/analysis/error_measures.hpp"

using namespace bendlab;

namespace {

// Exact fields at three nodes, with round numbers so that the expected errors are exact.
SurfaceFields three_nodes() {
  SurfaceFields a;
  a.normal.resize(3, 3);
  a.normal << 0, 0, 1, 1, 0, 0, 0, 1, 0;
  a.H = Scalars::Constant(3, 1.0);
  a.K = Scalars::Constant(3, 2.0);
  a.lapH = Scalars::Constant(3, -4.0);
  a.f_normal = Scalars::Constant(3, 8.0);
  a.f = 8.0 * a.normal;
  return a;
}

BendingResult exact_result(const SurfaceFields& a) {
  BendingResult r;
  r.normal = a.normal;
  r.H = a.H;
  r.K = a.K;
  r.lapH = a.lapH;
  r.force_density = a.f;
  return r;
}

const SurfaceMaxima kMaxima{2.0, 4.0, 8.0, 16.0};
}  // namespace

TEST(ErrorMeasures, ExactValuesGiveZeroError) {
  const SurfaceFields a = three_nodes();
  const NodeErrors e = node_errors(a, kMaxima, exact_result(a));
  for (Quantity q : kAllQuantities) {
    const ErrorSummary s = summarize(e[q]);
    EXPECT_TRUE(s.available) << to_string(q);
    EXPECT_EQ(s.max, 0.0) << to_string(q);
    EXPECT_EQ(s.average, 0.0) << to_string(q);
  }
}

TEST(ErrorMeasures, KnownPerturbationGivesKnownError) {
  const SurfaceFields a = three_nodes();
  BendingResult r = exact_result(a);
  r.H[1] += 1.0;                 // |dH| = 1, / max|H| = 2
  r.lapH[0] -= 2.0;              // |dlapH| = 2, / 8
  r.lapH[2] += 6.0;              // 6 / 8
  r.force_density.row(2) += Eigen::RowVector3d(3.0, 4.0, 0.0);  // |df| = 5, / 16
  r.normal.row(0) = Eigen::RowVector3d(0, 0, -1);               // opposite normal: |dn| = 2
  const NodeErrors e = node_errors(a, kMaxima, r);

  EXPECT_DOUBLE_EQ(e.H[1], 0.5);
  EXPECT_DOUBLE_EQ(summarize(e.H).max, 0.5);
  EXPECT_DOUBLE_EQ(summarize(e.H).average, 0.5 / 3);
  EXPECT_DOUBLE_EQ(summarize(e.lapH).max, 0.75);
  EXPECT_DOUBLE_EQ(summarize(e.lapH).average, (0.25 + 0.75) / 3);
  EXPECT_DOUBLE_EQ(summarize(e.f).max, 5.0 / 16);
  EXPECT_DOUBLE_EQ(summarize(e.f).average, 5.0 / 48);
  EXPECT_DOUBLE_EQ(summarize(e.n).max, 2.0);
  EXPECT_DOUBLE_EQ(summarize(e.n).average, 2.0 / 3);
  EXPECT_EQ(summarize(e.K).max, 0.0);
}

TEST(ErrorMeasures, DenominatorIsTheSurfaceMaximumNotTheLocalValue) {
  // A node where the exact value is zero still gets a finite relative error.
  Scalars a = Scalars::Zero(2), n(2);
  n << 0.1, -0.3;
  const Scalars e = scalar_errors(a, n, 0.5);
  EXPECT_DOUBLE_EQ(e[0], 0.2);
  EXPECT_DOUBLE_EQ(e[1], 0.6);
  EXPECT_THROW(scalar_errors(a, n, 0.0), Error);
  EXPECT_THROW(scalar_errors(a, n, kNaN), Error);
}

TEST(ErrorMeasures, UndefinedQuantitiesAreNotAvailable) {
  const SurfaceFields a = three_nodes();
  BendingResult r = exact_result(a);
  r.H = Scalars::Constant(3, kNaN);     // the method does not define H
  r.K.resize(0);                        // nor K (left empty)
  r.normal = Points::Constant(3, 3, kNaN);
  const NodeErrors e = node_errors(a, kMaxima, r);
  EXPECT_FALSE(summarize(e.H).available);
  EXPECT_FALSE(summarize(e.K).available);
  EXPECT_FALSE(summarize(e.n).available);
  EXPECT_EQ(e.K.size(), 3);
  EXPECT_TRUE(summarize(e.f).available);
  EXPECT_FALSE(summarize(Scalars()).available);
}

TEST(ErrorMeasures, PartlyNaNIsNotHidden) {
  Scalars e(3);
  e << 0.1, kNaN, 0.2;
  const ErrorSummary s = summarize(e);
  EXPECT_TRUE(s.available);
  EXPECT_TRUE(std::isnan(s.max));
  EXPECT_TRUE(std::isnan(s.average));
}

TEST(ErrorMeasures, WrongLengthThrows) {
  const SurfaceFields a = three_nodes();
  BendingResult r = exact_result(a);
  r.lapH = Scalars::Zero(2);
  EXPECT_THROW(node_errors(a, kMaxima, r), Error);
}

TEST(ErrorMeasures, QuantityNames) {
  for (Quantity q : kAllQuantities) EXPECT_EQ(parse_quantity(to_string(q)), q);
  EXPECT_EQ(to_string(Quantity::LapH), "lapH");
  EXPECT_THROW(parse_quantity("laph"), Error);
}

TEST(ErrorMeasures, VanishingFieldsUseTheirNaturalScale) {
  // On a sphere of radius 2, Lap H and f vanish: errors are relative to max|H|^3 = 1/8 and to
  // 2 kB max|H|^3 = kB / 4.
  auto sphere = make_sphere(2.0);
  Points x(2, 3);
  x << 2, 0, 0, 0, 0, -2;
  const double kB = 3.0;
  const SurfaceFields a = sphere->evaluate(x, kB);
  BendingResult r;
  r.normal = a.normal;
  r.H = a.H;
  r.K = a.K;
  r.lapH = Scalars::Constant(2, 0.01);
  r.force_density = Points::Zero(2, 3);
  r.force_density(1, 2) = 0.3;
  const NodeErrors e = node_errors(a, sphere->maxima(kB), r, kB);
  EXPECT_NEAR(e.lapH[0], 0.01 / 0.125, 1e-12);
  EXPECT_NEAR(e.f[0], 0.0, 1e-12);
  EXPECT_NEAR(e.f[1], 0.3 / (kB / 4), 1e-12);
}
