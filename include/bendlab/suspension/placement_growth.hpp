#pragma once
// Dense placement by growth, for the targets random sequential addition cannot reach
// (placement.hpp): in a tube 25 um across it jams at a tube hematocrit of 0.18 when 0.3 is asked,
// since randomly placed discs leave gaps no further disc fits into. Growing packers (Lubachevsky
// and Stillinger's for spheres; HemoCell's packCells for ellipsoids) start small and let the bodies
// push each other into room as they grow; this one does that for the cells' own meshes, as rigid
// bodies:
//   1. all the cells, shrunk by a scale s0 (0.6, then smaller while that jams), are placed by
//      random sequential addition from the seed with random orientations;
//   2. the scale grows in steps of 0.02 to 1; after each step the cells are pushed apart: every
//      vertex nearer than a target distance t (1.2 clearances, or 0.6 of the mean edge if that is
//      longer, so that a vertex cannot slip inside a coarse mesh between its vertices) to a vertex of another cell or to
//      the wall feels the smooth repulsion of contact.hpp, and each cell moves by the mean push of
//      its touching vertices and turns by their torque (over its radius of gyration squared),
//      until no vertex is nearer than t or the iterations run out;
//   3. at full size every pair of cells and every cell and the wall get the exact checks of
//      placement.hpp (vertex clearance and no vertex inside the other cell, on the meshes); where
//      one fails, the cells are pushed apart again with a larger t, a few rounds at most.
// Deterministic for a seed (one generator, cells and contacts in a fixed order). Cells stay rigid:
// the result is a rotation and a centre per cell, the reference shape's positions follow
// (placed_positions).
#include <cstdint>
#include <optional>
#include <vector>

#include "bendlab/core/types.hpp"
#include "bendlab/mesh/topology.hpp"
#include "bendlab/suspension/placement.hpp"
#include "bendlab/suspension/vessel.hpp"

namespace bendlab {

/// `count` cells of the reference shape (volume centroid at the origin) in the vessel, at least
/// `clearance` apart and from the wall with no vertex inside another cell; nothing where the
/// growth does not reach full size with every check passed.
std::optional<std::vector<PlacedCell>> grow_cells(const Vessel& vessel, const Topology& topology, const Points& reference,
                                                  int count, double clearance, std::uint64_t seed);

}  // namespace bendlab
