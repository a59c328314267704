#pragma once
// What a suspension run measures about its cells (shared/spec/CELLS_IN_CHANNELS.md section 3;
// docs/conventions.md §6), from plain per-vertex arrays, in any consistent units:
//   tube hematocrit       H_T = sum_c V_c / V_vessel;
//   discharge hematocrit  H_D = (flux of cell volume through a cross-section) / Q. Averaged over
//                         the cross-sections of one period, the flux of cell volume is
//                         sum_c V_c u_c / L, u_c the cell's velocity along x (here the mean of its
//                         vertices' velocities), so H_D = sum_c V_c u_c / (L Q);
//   cell-free layer       per slice of the vessel along x (and per wall of a channel), the wall
//                         distance of the outermost cell vertex in it, averaged over the slices
//                         (and walls) that hold a vertex;
//   row occupancy         for a line parallel to x, the fraction of its length in one period that
//                         lies inside cells (the local hematocrit of that line): each cell's
//                         triangles are cut by the line, and the crossings, sorted along x, pair
//                         up into the intervals inside. A profile of the local hematocrit across
//                         the section averages it over the lines of a radial (or z) bin.
#include <vector>

#include "bendlab/core/types.hpp"
#include "bendlab/mesh/topology.hpp"
#include "bendlab/suspension/vessel.hpp"

namespace bendlab {

/// The cells as rows of one position array: cell c holds rows [first[c], first[c] + count[c]).
struct CellRows {
  std::vector<Eigen::Index> first, count;
  std::vector<double> volume;  ///< the enclosed volume of each cell now
  std::vector<const Topology*> topology;  ///< each cell's triangles (for row_occupancy)
};

/// Lines parallel to x through the (y, z) points of a regular grid: y = y0 + j dy, z = z0 + k dz.
struct LineGrid {
  double y0 = 0, z0 = 0, dy = 1, dz = 1;
  int ny = 0, nz = 0;
};

double tube_hematocrit(const Vessel& vessel, const CellRows& cells);

/// H_D for the velocities U (rows as x) and the flow rate Q (volume per time through a
/// cross-section); 0 when Q is 0.
double discharge_hematocrit(const Vessel& vessel, const CellRows& cells, const Points& U, double flow_rate);

/// The mean cell-free layer over slices of `slice_width` along x (positions wrapped into the
/// period); NaN without cells. Throws bendlab::Error for a non-positive slice width.
double cell_free_layer(const Vessel& vessel, const Points& x, double slice_width);

/// The row occupancy of every line of `grid` (index j + ny k), in [0, 1]. A line that meets a
/// cell an odd number of times (through an edge or a vertex exactly) counts that cell as absent.
std::vector<double> row_occupancy(const Vessel& vessel, const CellRows& cells, const Points& x, const LineGrid& grid);

}  // namespace bendlab
