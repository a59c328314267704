#pragma once
// Whether a point lies inside a closed triangle mesh: the generalised winding number
//   w(p) = (1 / 4 pi) sum_faces Omega_f(p),
// Omega_f the signed solid angle of face f seen from p (Van Oosterom & Strackee 1983:
// tan(Omega/2) = a.(b x c) / (|a||b||c| + (a.b)|c| + (b.c)|a| + (c.a)|b|), a, b, c the corners
// relative to p). For a closed, outward-oriented mesh w = 1 inside and 0 outside, whatever the
// mesh's shape (no ray to cast, no degenerate hits); a point on the surface gives about 1/2.
// Cost: one solid angle per face; contains() first rejects points outside the bounding box.
#include "bendlab/core/types.hpp"
#include "bendlab/mesh/topology.hpp"

namespace bendlab {

/// w(p) for the mesh (topology, x).
double winding_number(const Topology& topology, const Points& x, const Vec3& p);

/// Axis-aligned bounding box of positions.
struct BoundingBox {
  Vec3 lo = Vec3::Zero(), hi = Vec3::Zero();
  bool contains(const Vec3& p, double margin = 0) const {
    return (p.array() >= lo.array() - margin).all() && (p.array() <= hi.array() + margin).all();
  }
};
BoundingBox bounding_box(const Points& x);

/// w(p) > 1/2, after a bounding-box test (`box` must be bounding_box(x)).
bool contains(const Topology& topology, const Points& x, const BoundingBox& box, const Vec3& p);

}  // namespace bendlab
