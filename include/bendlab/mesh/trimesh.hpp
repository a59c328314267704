#pragma once
// A validated closed triangle mesh: shared topology plus one set of vertex positions.
// Solvers that move vertices every step work on (Topology, Points) directly and build a TriMesh
// only where they need validation (input) or a self-contained shape (output).
#include <memory>

#include "bendlab/core/types.hpp"
#include "bendlab/mesh/topology.hpp"

namespace bendlab {

struct MeshOptions {
  /// When the enclosed volume is negative (faces clockwise seen from outside), reverse every
  /// face instead of refusing the mesh.
  bool flip_inward = false;
};

class TriMesh {
 public:
  /// Validates topology (see Topology::build) and geometry: NonFinite coordinates, ZeroArea
  /// triangles, InwardOrientation (unless options.flip_inward). Throws MeshError.
  TriMesh(Points positions, const Faces& faces, MeshOptions options = {});
  /// Same topology, new positions (validated for NonFinite and ZeroArea, and orientation).
  TriMesh(TopologyPtr topology, Points positions);

  const Topology& topology() const { return *topology_; }
  const TopologyPtr& topology_ptr() const { return topology_; }
  const Points& positions() const { return positions_; }
  const Faces& faces() const { return topology_->faces(); }
  int num_vertices() const { return topology_->num_vertices(); }
  int num_faces() const { return topology_->num_faces(); }
  Vec3 position(int i) const { return positions_.row(i).transpose(); }

  /// A mesh with the same (shared) topology and other positions.
  TriMesh with_positions(Points positions) const { return TriMesh(topology_, std::move(positions)); }

 private:
  TopologyPtr topology_;
  Points positions_;
};

/// Throws MeshError(NonFinite) or MeshError(ZeroArea) naming the first offending vertex or face.
void validate_geometry(const Topology& topology, const Points& positions);

}  // namespace bendlab
