// The tree rule of the single layer (flow/bim/single_layer_tree.cpp) against all7.
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

TEST(StokesSingleLayer, TreeNamesAndOptions) {
  EXPECT_EQ(single_layer_quadrature("tree"), SingleLayerQuadrature::tree);
  EXPECT_EQ(to_string(SingleLayerQuadrature::tree), "tree");
  const TriMesh m = sphere_mesh(MeshFamily::MT1, 0);
  SingleLayerOptions o = tree_rule();
  o.tree_ratio = 1.0;  // a box at a node could be far
  EXPECT_THROW(StokesSingleLayer(m.topology_ptr(), o), Error);
  o = tree_rule();
  o.tree_leaf_size = 0;
  EXPECT_THROW(StokesSingleLayer(m.topology_ptr(), o), Error);
  o = tree_rule();
  o.tree_order = 9;
  EXPECT_THROW(StokesSingleLayer(m.topology_ptr(), o), Error);
  o = tree_rule();
  o.tree_tolerance = -1e-6;
  EXPECT_THROW(StokesSingleLayer(m.topology_ptr(), o), Error);
}

TEST(StokesSingleLayer, TreeWithoutFarFieldIsAll7) {
  // With no cluster far, every target sums the 7-point rule over every face, in another order.
  const Case c = quadrature_case(1280, true);
  const double e = relative_difference(single_layer(c, tree_rule(0.0, 1e100)),
                                       single_layer(c, with(SingleLayerQuadrature::all7)));
  EXPECT_LT(e, 1e-13);
}

TEST(StokesSingleLayer, TreeZeroForceGivesZeroVelocity) {
  Case c = quadrature_case(1280, false);
  c.f.setZero();
  const Points u = single_layer(c, tree_rule());
  EXPECT_EQ(u.cwiseAbs().maxCoeff(), 0.0);
}

TEST(StokesSingleLayer, TreeTranslationInvariant) {
  // Translating the shape moves its centroids, boxes and proxies alike, but rounding breaks the
  // ties between equal centroid coordinates of the symmetric mesh differently, so the k-d splits
  // (and the clusters) can differ: the velocities agree to the rule's bound, 1e-5 of all7 each.
  const Case c = quadrature_case(1280, true);
  Case shifted = c;
  shifted.x.rowwise() += Vec3(0.375, -0.25, 0.125).transpose();
  const double e = relative_difference(single_layer(shifted, tree_rule()), single_layer(c, tree_rule()));
  EXPECT_LT(e, 2e-5);
}

TEST(StokesSingleLayer, TreeDifferenceFollowsTolerance) {
  // The far field is accepted where its error estimate is below tree_tolerance times the scale of
  // the velocity: a hundred times smaller a tolerance, a difference from all7 at least ten times smaller.
  const Case c = quadrature_case(1280, true);
  const Points ref = single_layer(c, with(SingleLayerQuadrature::all7));
  const double e5 = relative_difference(single_layer(c, tree_rule(1e-5)), ref);
  const double e7 = relative_difference(single_layer(c, tree_rule(1e-7)), ref);
  ::testing::Test::RecordProperty("tolerance_1e-5_1e-7", scientific(e5) + " " + scientific(e7));
  EXPECT_GT(e5 / e7, 10.0);
  EXPECT_GT(e7, 0.0);
}

TEST(StokesSingleLayer, TreeWithin1e5OfAll7At1280) { expect_tree_within_1e5(1280); }

TEST(StokesSingleLayer, TreeWithin1e5OfAll7At5120) {
#if defined(__SANITIZE_ADDRESS__)
  GTEST_SKIP() << "5120 triangles: too slow under the sanitizers (1280 runs there)";
#else
  expect_tree_within_1e5(5120);
#endif
}

// tree-mixed: the tree's terms with its sums in single precision (stokes_single_layer.hpp).
