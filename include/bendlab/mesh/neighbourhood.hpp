#pragma once
// Neighbourhood queries on a Topology (conventions in topology.hpp: faces counter-clockwise seen
// from outside, one-rings counter-clockwise about the outward normal).
//
//   k-ring of a vertex   the vertices at graph distance 1..k (Method E's fitting support);
//   one-ring faces       the faces around a vertex, counter-clockwise;
//   face patch           the vertices of the faces that touch a face (the support of a Loop
//                        subdivision patch, e.g. for evaluating the limit surface on that face).
#include <span>
#include <vector>

#include "bendlab/mesh/topology.hpp"

namespace bendlab {

/// Breadth-first rings around one vertex at a time, in buffers reused from vertex to vertex (make
/// one per thread). Order of vertices(): ring 1 as the CSR one-ring (counter-clockwise, starting
/// at ring_vertices()[ring_begin(i)]); each further ring in the order of discovery: for each
/// vertex of the previous ring, in list order, its unseen one-ring neighbours counter-clockwise.
/// The centre itself is never listed.
class VertexRings {
 public:
  explicit VertexRings(const Topology& topology) : t_(topology) {}

  /// Starts at vertex i with ring 1. Throws bendlab::Error for an index out of range.
  void start(int i);
  /// Adds the next ring; false (nothing added) when the rings already cover i's connected mesh.
  bool add_ring();
  /// Adds rings until there are k of them (or the mesh is covered); returns rings().
  int grow_to(int k);

  int centre() const { return centre_; }
  int rings() const { return rings_; }
  const std::vector<int>& vertices() const { return list_; }

 private:
  const Topology& t_;
  int centre_ = -1, rings_ = 0;
  bool stamped_ = false;
  std::size_t last_ring_begin_ = 0;
  std::vector<int> list_;
  unsigned stamp_ = 0;          ///< this start's mark (a new one at every start that goes beyond ring 1)
  std::vector<unsigned> mark_;  ///< mark_[v] == stamp_: v already collected (or is the centre)
};

/// The vertices at graph distance 1..k from vertex i, in VertexRings order (k = 0: none).
/// Throws bendlab::Error for i out of range or k < 0.
std::vector<int> k_ring(const Topology& topology, int i, int k);

/// The faces around vertex i, counter-clockwise: face k is (i, j_k, j_{k+1}) of the one-ring
/// (a view of Topology::ring_faces()). Throws bendlab::Error for i out of range.
std::span<const int> one_ring_faces(const Topology& topology, int i);

/// The patch of face f = (a, b, c): every vertex of a face that shares a vertex with f.
/// Order: a, b, c (f's corners in its own order), then the other vertices in one
/// counter-clockwise loop around f seen from outside: the outer one-ring of a from the vertex
/// across edge (c, a) to the vertex across edge (a, b), then that of b on to the vertex across
/// (b, c), then that of c, each vertex once. With valences v_a, v_b, v_c >= 4 the patch has
/// v_a + v_b + v_c - 6 vertices: 12 for a regular face (all valences 6), the layout of a regular
/// Loop box-spline patch. Throws bendlab::Error for f out of range.
std::vector<int> face_patch(const Topology& topology, int f);

}  // namespace bendlab
