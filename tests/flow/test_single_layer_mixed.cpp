// The single-precision tree (flow/bim/single_layer_mixed.cpp) against the tree in double and all7.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "bendlab/flow/bim/stokes_single_layer.hpp"
#include "bendlab/mesh/generators.hpp"
#include "flow/single_layer_test_support.hpp"

using namespace bendlab;
using namespace bendlab::test_support;

TEST(StokesSingleLayer, TreeMixedNames) {
  EXPECT_EQ(single_layer_quadrature("tree-mixed"), SingleLayerQuadrature::tree_mixed);
  EXPECT_EQ(to_string(SingleLayerQuadrature::tree_mixed), "tree-mixed");
  EXPECT_THROW(single_layer_quadrature("tree_mixed"), Error);
}

namespace {
// max_i |u_mixed - u_tree| / max_i |u_tree| on both shapes: the rounding of single precision
// alone (the same clusters, proxies and terms), below `bound` and not zero.
void expect_mixed_near_tree(int triangles, double bound) {
  const SingleLayerOptions defaults;
  for (bool rbc : {true, false}) {
    const Case c = quadrature_case(triangles, rbc);
    const double e = relative_difference(
        single_layer(c, tree_rule(defaults.tree_tolerance, defaults.tree_ratio, SingleLayerQuadrature::tree_mixed)),
        single_layer(c, tree_rule()));
    ::testing::Test::RecordProperty(rbc ? "rbc" : "ellipsoid", scientific(e));
    const std::string what = std::string(rbc ? "red blood cell" : "ellipsoid 2:1:0.5") + ", " +
                             std::to_string(triangles) + " triangles";
    EXPECT_LT(e, bound) << what;
    EXPECT_GT(e, 1e-12) << what << ": the single-precision sums were not used";
  }
}
}  // namespace

TEST(StokesSingleLayer, TreeMixedWithinSinglePrecisionOfTreeAt1280) { expect_mixed_near_tree(1280, 1e-6); }

TEST(StokesSingleLayer, TreeMixedPaddingToWholeBlocksAddsNothing) {
  // Leaves of 1, 3 and 5 faces (7, 21, 35 points) and degrees 2, 3 and 5 (10, 20, 56 proxies):
  // none a whole number of the kernel's blocks, so every range carries zero-weight padding. The
  // single-precision sums stay as close to the double tree as with the default layout.
  for (bool rbc : {true, false}) {
    const Case c = quadrature_case(320, rbc);
    for (const auto& [leaf, degree] : {std::pair{1, 2}, std::pair{3, 3}, std::pair{5, 5}}) {
      SingleLayerOptions tree = tree_rule();
      tree.tree_leaf_size = leaf;
      tree.tree_order = degree;
      SingleLayerOptions mixed = tree;
      mixed.quadrature = SingleLayerQuadrature::tree_mixed;
      const Points u = single_layer(c, mixed);
      ASSERT_TRUE(u.allFinite());
      const double e = relative_difference(u, single_layer(c, tree));
      EXPECT_LT(e, 1e-6) << (rbc ? "red blood cell" : "ellipsoid") << ", leaf " << leaf << ", degree " << degree;
      EXPECT_GT(e, 1e-12);
    }
  }
}

TEST(StokesSingleLayer, TreeMixedWithoutFarFieldNearAll7) {
  // Every face near: the 7-point rule over every face in single precision, against all7 in double.
  const Case c = quadrature_case(1280, true);
  const double e = relative_difference(single_layer(c, tree_rule(0.0, 1e100, SingleLayerQuadrature::tree_mixed)),
                                       single_layer(c, with(SingleLayerQuadrature::all7)));
  ::testing::Test::RecordProperty("difference", scientific(e));
  EXPECT_LT(e, 1e-6);
  EXPECT_GT(e, 1e-12);
}

TEST(StokesSingleLayer, TreeMixedZeroForceGivesZeroVelocity) {
  Case c = quadrature_case(1280, false);
  c.f.setZero();
  const Points u = single_layer(c, tree_rule(SingleLayerOptions{}.tree_tolerance, SingleLayerOptions{}.tree_ratio,
                                             SingleLayerQuadrature::tree_mixed));
  EXPECT_EQ(u.cwiseAbs().maxCoeff(), 0.0);
}

TEST(StokesSingleLayer, TreeMixedWithin1e5OfAll7At1280) { expect_tree_within_1e5(1280, SingleLayerQuadrature::tree_mixed); }

TEST(StokesSingleLayer, TreeMixedAt5120) {
#if defined(__SANITIZE_ADDRESS__)
  GTEST_SKIP() << "5120 triangles: too slow under the sanitizers (1280 runs there)";
#else
  expect_mixed_near_tree(5120, 1e-6);
  expect_tree_within_1e5(5120, SingleLayerQuadrature::tree_mixed);
#endif
}
