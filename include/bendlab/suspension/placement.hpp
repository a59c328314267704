#pragma once
// Cells placed in a vessel at a target tube hematocrit H_T = N V_cell / V_vessel (or a number of
// cells), from a seed, with no overlap (shared/spec/CELLS_IN_CHANNELS.md section 2;
// docs/conventions.md §6).
//
// Random sequential addition: each cell in turn gets a random centre in the vessel and an
// orientation, and is kept when
//   - every vertex lies at least `clearance` from the wall;
//   - no vertex lies nearer than `clearance` to a vertex of a cell already placed (nearest
//     periodic image), and
//   - no vertex of either lies inside the other (winding number on the meshes, point_in_mesh.hpp),
// so that overlap is checked on the meshes, not on bounding spheres (a vertex outside the other
// cell's box in that cell's own frame skips the tests, which could not fail there). The first
// half of a cell's attempts draws uniformly random orientations; the second half aligns the
// cell's axis of symmetry (the reference shape's z axis: a red blood cell's) with the flow (x),
// spun at random about it and tilted by up to 30 degrees, centred near the axis (in a tube: in the
// widest gap between the cells placed along it, jittered by a quarter of the gap), which is how
// cells stack in a narrow tube. In a tube less than two cell diameters across every attempt is
// aligned, and cell c goes to the slot x0 + (c + 1/2) L / N (x0 from the seed): random
// orientations and positions there leave gaps no later cell fits into. Its tilt (up to 30
// degrees), its offset from the axis and its jitter in the slot (up to half a slot) shrink
// linearly over the attempts, down to a cell square to the axis in the middle of its slot.
//
// Growth, where random addition jams. A cell once placed never moves, so random addition stops
// well below the tube hematocrits of blood-flow studies (the 25 x 50 um tube of
// bench_suspension at H_T 0.18 of 0.3; a 10 um tube short of 0.4). When a cell fails its attempts,
// all N cells are placed again by random addition at s0 = 0.6 of their size (0.45, then 0.3, if
// that fails too; from a seed derived from the given one), which a fifth of the volume makes
// easy, and grown to full size as rigid bodies (cell_growth.hpp): the scale rises in steps, and
// after each the cells are pushed apart and turned by their overlaps (the vertices of one within
// clearance + margin of the surface of another or of the wall; margin = 0.1 clearance + 0.002
// cell radius) until none is left. Growing lets the cells rearrange as the space fills, which
// random addition cannot, while each stays the rigid reference shape (a rotation and a centre);
// it reaches H_T 0.4 in 10 um tubes and 0.3 in 15 to 25 um tubes and 12 to 20 um channels in
// seconds. A narrow tube stacks the shrunk cells in slots only where N full-size cells stacked
// square fit along it (N (thickness + clearance) <= L); else they start at random. The grown
// cells are then checked exactly as random addition checks them (vertex clearance and the
// winding number both ways, periodic images of a cell itself included; wall clearance).
// Targets random addition reaches take no part of this: they place the same cells as before.
//
// A target that neither reaches is refused with an Error that states the best reached by random
// addition (cells placed, H_T) and by growth (the scale reached and its H_T); nothing is
// returned half-placed.
#include <cstdint>
#include <optional>
#include <vector>

#include "bendlab/core/types.hpp"
#include "bendlab/mesh/topology.hpp"
#include "bendlab/suspension/vessel.hpp"

namespace bendlab {

struct PlacementOptions {
  std::optional<double> hematocrit;  ///< target H_T; or
  std::optional<int> count;          ///< a number of cells
  double clearance = 0;              ///< least vertex distance between cells and to the wall
  std::uint64_t seed = 1;
  int attempts_per_cell = 4000;
};

struct PlacedCell {
  Mat3 rotation = Mat3::Identity();
  Vec3 centre = Vec3::Zero();
};

struct Placement {
  std::vector<PlacedCell> cells;
  double hematocrit = 0;  ///< achieved: cells x cell volume / vessel volume
  double cell_volume = 0;
  std::int64_t attempts = 0;
  double initial_scale = 1;  ///< 1: placed at full size; else the scale the cells were grown from
  std::int64_t sweeps = 0;   ///< relaxation sweeps of the growth
};

/// The reference shape (topology, reference: vertex positions with the volume centroid at the
/// origin) rotated and moved into place.
Points placed_positions(const Points& reference, const PlacedCell& cell);

/// Throws bendlab::Error for a negative, non-finite or unreachable target (with the best
/// reached), a cell that cannot fit in the vessel, or neither or both of hematocrit and count.
Placement place_cells(const Vessel& vessel, const Topology& topology, const Points& reference,
                      const PlacementOptions& options);

}  // namespace bendlab
