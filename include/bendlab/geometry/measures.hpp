#pragma once
// Global measures of a closed triangle mesh (flat triangles). The enclosed volume lives with the
// mesh (bendlab/mesh/enclosed_volume.hpp, included here), which needs it to check orientation.
#include "bendlab/core/types.hpp"
#include "bendlab/mesh/enclosed_volume.hpp"  // enclosed_volume()
#include "bendlab/mesh/topology.hpp"

namespace bendlab {

/// Total area of the flat triangles.
double surface_area(const Topology& topology, const Points& x);
/// Centroid of the enclosed volume (not of the nodes), from surface integrals.
Vec3 volume_centroid(const Topology& topology, const Points& x);
/// Mean length of the edges, each counted once: the h of the paper's convergence plots.
double mean_edge_length(const Topology& topology, const Points& x);
/// Smallest corner angle over all triangles, in radians.
double min_corner_angle(const Topology& topology, const Points& x);

struct ValenceStats {
  int min = 0, max = 0;
  double mean = 0;
  std::vector<int> histogram;  ///< histogram[d] = number of vertices with d neighbours
};
ValenceStats valence_stats(const Topology& topology);

}  // namespace bendlab
