// The suspension's measures (flow_measures.hpp) on configurations whose values are known exactly.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "bendlab/mesh/enclosed_volume.hpp"
#include "bendlab/mesh/generators.hpp"
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

// The lines' occupancies, times the period and the area each line stands for, add up to the cells'
// volume (a midpoint rule over the section, converging as the grid refines); lines that miss the
// cells are empty; a line through the centre of a sphere is inside over its diameter.
TEST(FlowMeasures, RowOccupancyIntegratesToTheCellVolume) {
  const TriMesh sphere = sphere_mesh(MeshFamily::MT1, 4);  // 5120 triangles
  const Vessel tube = Vessel::tube(10.0, 8.0);
  Points x(2 * sphere.num_vertices(), 3);
  x.topRows(sphere.num_vertices()) = 2.0 * sphere.positions();
  x.bottomRows(sphere.num_vertices()) = 1.5 * sphere.positions();
  x.bottomRows(sphere.num_vertices()).rowwise() += Vec3(5.0, 1.0, -2.0).transpose();  // crosses x = L/2: unwrapped
  CellRows cells;
  cells.first = {0, sphere.num_vertices()};
  cells.count = {sphere.num_vertices(), sphere.num_vertices()};
  cells.topology = {&sphere.topology(), &sphere.topology()};
  double volume = 0;
  for (int c = 0; c < 2; ++c) {
    const Points xc = x.middleRows(cells.first[c], cells.count[c]);
    cells.volume.push_back(enclosed_volume(sphere.topology(), xc));
    volume += cells.volume.back();
  }
  for (int n : {40, 80}) {
    LineGrid g;
    g.dy = g.dz = 10.0 / n;
    g.y0 = g.z0 = -5.0 + 0.5 * g.dy;
    g.ny = g.nz = n;
    const std::vector<double> occ = row_occupancy(tube, cells, x, g);
    double sum = 0;
    for (double o : occ) sum += o * tube.length() * g.dy * g.dz;
    EXPECT_NEAR(sum, volume, (n == 40 ? 0.01 : 0.004) * volume) << n;
    // The line nearest the first sphere's centre (0.18 or 0.09 from it): inside over about its diameter.
    const int mid = n / 2;
    EXPECT_NEAR(occ[mid + static_cast<std::size_t>(n) * mid] * tube.length(), 4.0, 0.02);
    // A line far from both cells.
    EXPECT_EQ(occ[static_cast<std::size_t>(n) * (n - 1)], 0.0);
  }
}
