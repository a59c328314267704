#pragma once
// The exact checks of a placement (placement.hpp, placement_growth.hpp), shared by its two ways of
// placing cells: a cell's vertices clear of the wall, and two cells apart on their meshes.
#include <random>

#include "bendlab/core/types.hpp"
#include "bendlab/geometry/point_in_mesh.hpp"
#include "bendlab/mesh/topology.hpp"
#include "bendlab/suspension/vessel.hpp"

namespace bendlab::placement_detail {

struct Candidate {
  Points x;
  BoundingBox box;
  Vec3 centre;
  Mat3 rotation = Mat3::Identity();  ///< x = reference rotation^T + centre
};

/// Shoemake's uniform random rotation.
Mat3 random_rotation(std::mt19937_64& rng);

/// Every vertex of x at least `clearance` from the wall.
bool clear_of_wall(const Vessel& v, const Points& x, double clearance);

/// Whether cells a and b (b shifted by `shift`, a periodic image) keep the clearance and neither
/// holds a vertex of the other. A vertex is first set against the other cell's box in that cell's
/// own frame (`frame_box`, the reference's box, widened by `slack` against rounding): outside it,
/// widened by the clearance, it is near none of the other's vertices, and outside it, inside none
/// of it, so the tests it skips could not fail and the answer is the same.
bool apart(const Topology& topo, const Candidate& a, const Candidate& b, const Vec3& shift, double clearance,
           const BoundingBox& frame_box, double slack);

}  // namespace bendlab::placement_detail
