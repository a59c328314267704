// The suspension recorder's statistics: the standard error of ten batch means.
#include <gtest/gtest.h>

#include <cmath>
#include <numeric>

#include "bendlab/flow/suspension_recorder.hpp"

using namespace bendlab;

TEST(SuspensionRecorder, StandardErrorOfTenBatchMeans) {
  // 0, 1, ..., 99: batches of ten with means 4.5, 14.5, ..., 94.5, whose sample standard
  // deviation is 10 sqrt(110 / 12) = 30.2765; over sqrt(10).
  std::vector<double> v(100);
  std::iota(v.begin(), v.end(), 0.0);
  const MeanWithError m = mean_with_error(v);
  EXPECT_DOUBLE_EQ(m.mean, 49.5);
  EXPECT_NEAR(m.standard_error, 10 * std::sqrt(110.0 / 12.0) / std::sqrt(10.0), 1e-12);
  EXPECT_EQ(m.rows, 100);
  // Fewer than 20 rows: the rows' own standard error. 1, 2, 3: sd 1, over sqrt(3).
  const MeanWithError few = mean_with_error({1, 2, 3});
  EXPECT_DOUBLE_EQ(few.mean, 2.0);
  EXPECT_NEAR(few.standard_error, 1 / std::sqrt(3.0), 1e-15);
  EXPECT_TRUE(std::isnan(mean_with_error({}).mean));
  // A constant series has no error (but the round-off of its batch means).
  EXPECT_NEAR(mean_with_error(std::vector<double>(50, 0.3)).standard_error, 0.0, 1e-15);
}
