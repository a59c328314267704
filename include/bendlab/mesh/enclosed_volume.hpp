#pragma once
// The volume enclosed by a closed triangle mesh: what TriMesh needs to tell outward from inward
// faces. The other global measures (area, centroid, edge lengths, angles) are in
// bendlab/geometry/measures.hpp, which includes this header.
#include "bendlab/core/types.hpp"
#include "bendlab/mesh/topology.hpp"

namespace bendlab {

/// Enclosed volume by the divergence theorem, (1/6) sum_f x0 . (x1 x x2): positive for outward faces.
double enclosed_volume(const Topology& topology, const Points& x);

}  // namespace bendlab
