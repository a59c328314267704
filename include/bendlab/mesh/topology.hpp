#pragma once
// Connectivity of a closed, orientable, 2-manifold triangle mesh, built and validated once and
// shared (read-only) by every shape that uses it: a time series of capsule shapes, the sphere and
// the RBC mapped from it, ...
//
// Conventions
// - Faces are counter-clockwise seen from outside (outward face normals).
// - Edge e joins edge_vertices(e) = (a, b) with a < b. edge_faces(e) = (f0, f1): f0 traverses the
//   edge as a -> b, f1 as b -> a. edge_opposite(e) = (o0, o1): the vertex of f0 (f1) not on e.
// - face_edges(f, k) is the edge opposite corner k of face f, i.e. between corners k+1 and k+2.
// - One-rings (CSR, ring_begin(i) .. ring_end(i)): neighbours j_0 .. j_{d-1} of vertex i in
//   counter-clockwise order about the outward normal; ring_faces()[k] is the face (i, j_k, j_{k+1})
//   (indices mod d), ring_edges()[k] the edge (i, j_k), ring_corners()[k] the corner (0..2) of i
//   in ring_faces()[k]. So the faces around a vertex are the same CSR slice.
#include <atomic>
#include <cstdint>
#include <memory>
#include <vector>

#include "bendlab/core/types.hpp"
#include "bendlab/mesh/mesh_error.hpp"

namespace bendlab {

class Topology {
 public:
  /// Builds the connectivity and validates it. Throws MeshError naming the first offending
  /// element: IndexOutOfRange, RepeatedIndex, UnreferencedVertex, NonManifoldEdge, BoundaryEdge,
  /// InconsistentOrientation, NonManifoldVertex, Empty.
  static std::shared_ptr<const Topology> build(int num_vertices, const Faces& faces);

  int num_vertices() const { return num_vertices_; }
  int num_faces() const { return static_cast<int>(faces_.rows()); }
  int num_edges() const { return static_cast<int>(edge_vertices_.rows()); }

  const Faces& faces() const { return faces_; }
  const IndexPairs& edge_vertices() const { return edge_vertices_; }
  const IndexPairs& edge_faces() const { return edge_faces_; }
  const IndexPairs& edge_opposite() const { return edge_opposite_; }
  /// The corners (0..2) of edge_faces(e) at edge_opposite(e): face_edges(f_s, corner) == e.
  const IndexPairs& edge_opposite_corners() const { return edge_opposite_corners_; }
  const Faces& face_edges() const { return face_edges_; }

  int ring_begin(int i) const { return ring_offsets_[i]; }
  int ring_end(int i) const { return ring_offsets_[i + 1]; }
  int valence(int i) const { return ring_offsets_[i + 1] - ring_offsets_[i]; }
  const std::vector<int>& ring_offsets() const { return ring_offsets_; }
  const std::vector<int>& ring_vertices() const { return ring_vertices_; }
  const std::vector<int>& ring_faces() const { return ring_faces_; }
  const std::vector<int>& ring_edges() const { return ring_edges_; }
  const std::vector<int>& ring_corners() const { return ring_corners_; }

  /// Euler characteristic V - E + F (2 for a sphere).
  int euler_characteristic() const { return num_vertices() - num_edges() + num_faces(); }

  /// A number no other Topology object of this process has had, a copy included. Buffers kept
  /// for one connectivity (a method's per-thread workspace) are keyed on it, not on the object's
  /// address: a topology freed and another built may share an address (the allocator reuses the
  /// block), and a buffer sized for the first would then be indexed by the second's vertices.
  std::uint64_t id() const { return id_.value; }

 private:
  // A fresh number for every object, also for a copy or an assignment.
  struct Identity {
    static std::uint64_t next() {
      static std::atomic<std::uint64_t> counter{0};
      return ++counter;
    }
    Identity() : value(next()) {}
    Identity(const Identity&) : value(next()) {}
    Identity& operator=(const Identity&) {
      value = next();
      return *this;
    }
    std::uint64_t value;
  };

  Topology() = default;
  Identity id_;
  int num_vertices_ = 0;
  Faces faces_;
  IndexPairs edge_vertices_, edge_faces_, edge_opposite_, edge_opposite_corners_;
  Faces face_edges_;
  std::vector<int> ring_offsets_, ring_vertices_, ring_faces_, ring_edges_, ring_corners_;
};

using TopologyPtr = std::shared_ptr<const Topology>;

}  // namespace bendlab
