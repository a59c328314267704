#include <gtest/gtest.h>

#include "bendlab/parallel/slab_decomposition.hpp"

using namespace bendlab;
using namespace bendlab::parallel;

TEST(SlabDecomposition, CoversEveryLayerOnceInRankOrder) {
  for (int ny : {1, 5, 12, 13}) {
    for (int ranks = 1; ranks <= std::min(ny, 5); ++ranks) {
      int next = 0;
      for (int r = 0; r < ranks; ++r) {
        const SlabDecomposition s = SlabDecomposition::of(ny, ranks, r);
        EXPECT_EQ(s.begin, next);
        EXPECT_GE(s.count, ny / ranks);
        EXPECT_LE(s.count, ny / ranks + 1);
        for (int j = s.begin; j < s.begin + s.count; ++j) {
          EXPECT_EQ(s.owner(j), r) << "ny " << ny << " ranks " << ranks << " j " << j;
          EXPECT_TRUE(s.owns(j));
        }
        next = s.begin + s.count;
      }
      EXPECT_EQ(next, ny);
    }
  }
}

TEST(SlabDecomposition, RefusesMoreRanksThanLayers) {
  EXPECT_THROW(SlabDecomposition::of(3, 4, 0), Error);
  EXPECT_THROW(SlabDecomposition::of(8, 2, 2), Error);
}

TEST(SlabDecomposition, FaceSlotsAreTheFivePopulationsCrossingEachFace) {
  for (int s = 0; s < kFacePopulations; ++s) {
    EXPECT_EQ(lbm::kCy[kLowerFaceSlots[s]], -1);
    EXPECT_EQ(lbm::kCy[kUpperFaceSlots[s]], 1);
    EXPECT_EQ(lbm::opposite(kLowerFaceSlots[s]), kUpperFaceSlots[s]);
  }
  lbm::LatticeConfig c;
  c.nx = 7;
  c.ny = 9;
  c.nz = 11;
  EXPECT_EQ(halo_bytes_per_step(c), 2u * 5u * 7u * 11u * 8u);
}
