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
// so that overlap is checked on the meshes, not on bounding spheres. The first half of a cell's
// attempts draws uniformly random orientations; the second half aligns the cell's axis of
// symmetry (the reference shape's z axis: a red blood cell's) with the flow (x), spun at random
// about it and tilted by up to 30 degrees, centred near the axis (in a tube: in the widest gap
// between the cells placed along it, jittered by a quarter of the gap), which is how cells stack
// in a narrow tube. In a tube less than two cell diameters across every attempt is aligned, and
// cell c goes to the slot x0 + (c + 1/2) L / N (x0 from the seed): random orientations and
// positions there leave gaps no later cell fits into. Its tilt (up to 30 degrees), its offset from
// the axis and its jitter in the slot (up to half a slot) shrink linearly over the attempts, down to
// a cell square to the axis in the middle of its slot. Where a cell finds no room within its
// attempts, every cell is placed again by growth (placement_growth.hpp: shrunk, placed, grown to
// full size as rigid bodies pushed apart, then checked exactly as here). A target that neither
// reaches is refused with an Error that states the best reached; nothing is returned half-placed.
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
  bool grown = false;     ///< placed by growth (placement_growth.hpp) after the random addition jammed
};

/// The reference shape (topology, reference: vertex positions with the volume centroid at the
/// origin) rotated and moved into place.
Points placed_positions(const Points& reference, const PlacedCell& cell);

/// Throws bendlab::Error for a negative, non-finite or unreachable target (with the best
/// reached), a cell that cannot fit in the vessel, or neither or both of hematocrit and count.
Placement place_cells(const Vessel& vessel, const Topology& topology, const Points& reference,
                      const PlacementOptions& options);

}  // namespace bendlab
