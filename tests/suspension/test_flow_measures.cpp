// The suspension's measures (flow_measures.hpp) on configurations whose values are known exactly.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "bendlab/suspension/flow_measures.hpp"

using namespace bendlab;

TEST(FlowMeasures, HematocritsOfCellsMovingWithKnownVelocities) {
  const Vessel tube = Vessel::tube(10.0, 20.0);
  CellRows cells;
  cells.first = {0, 3};
  cells.count = {3, 2};
  cells.volume = {90.0, 100.0};
  EXPECT_NEAR(tube_hematocrit(tube, cells), 190.0 / (std::numbers::pi * 25.0 * 20.0), 1e-15);
  Points U(5, 3);
  U << 1, 0, 0, 2, 5, 0, 3, 0, -1,  // cell 0: mean u_x = 2
      4, 0, 0, 4, 1, 1;             // cell 1: mean u_x = 4
  const double Q = 500.0;
  EXPECT_NEAR(discharge_hematocrit(tube, cells, U, Q), (90.0 * 2 + 100.0 * 4) / (20.0 * 500.0), 1e-15);
  // Cells moving with the mean velocity of the fluid (Q / A): H_D = H_T.
  const double mean = Q / (std::numbers::pi * 25.0);
  Points same = Points::Constant(5, 3, 0.0);
  same.col(0).setConstant(mean);
  EXPECT_NEAR(discharge_hematocrit(tube, cells, same, Q), tube_hematocrit(tube, cells), 1e-14);
  EXPECT_EQ(discharge_hematocrit(tube, cells, U, 0.0), 0.0);
}

TEST(FlowMeasures, CellFreeLayerIsTheMeanDistanceOfTheOutermostVertexPerSlice) {
  const Vessel tube = Vessel::tube(10.0, 20.0);
  Points x(4, 3);
  x << -8.0, 3.0, 0.0,   // slice 0 (of 2): r = 3, 2 from the wall
      -6.0, 0.0, 1.0,    // slice 0: r = 1
      4.0, 0.0, -4.0,    // slice 1: r = 4, 1 from the wall
      26.0, 0.5, 0.0;    // x = 26 wraps to 6: slice 1, r = 0.5
  EXPECT_NEAR(cell_free_layer(tube, x, 10.0), (2.0 + 1.0) / 2, 1e-14);
  // One slice over the whole tube: the outermost vertex overall.
  EXPECT_NEAR(cell_free_layer(tube, x, 20.0), 1.0, 1e-14);
  // A channel counts each wall apart: top (z > 0) and bottom.
  const Vessel channel = Vessel::channel(10.0, 4.0, 20.0);
  EXPECT_NEAR(cell_free_layer(channel, x, 20.0), ((5.0 - 1.0) + (5.0 - 4.0)) / 2, 1e-14);
  EXPECT_TRUE(std::isnan(cell_free_layer(tube, Points(0, 3), 5.0)));
  EXPECT_THROW(cell_free_layer(tube, x, 0.0), Error);
}
