// k-rings, one-ring faces and face patches (mesh/neighbourhood.hpp).
#include <gtest/gtest.h>

#include <algorithm>
#include <set>

#include "bendlab/mesh/generators.hpp"
#include "bendlab/mesh/neighbourhood.hpp"

using namespace bendlab;

namespace {

bool adjacent(const Topology& t, int a, int b) {
  for (int k = t.ring_begin(a); k < t.ring_end(a); ++k)
    if (t.ring_vertices()[k] == b) return true;
  return false;
}

// Graph distance from i to every vertex, by plain breadth-first search.
std::vector<int> distances(const Topology& t, int i) {
  std::vector<int> d(t.num_vertices(), -1), queue = {i};
  d[i] = 0;
  for (std::size_t q = 0; q < queue.size(); ++q)
    for (int k = t.ring_begin(queue[q]); k < t.ring_end(queue[q]); ++k) {
      const int j = t.ring_vertices()[k];
      if (d[j] < 0) {
        d[j] = d[queue[q]] + 1;
        queue.push_back(j);
      }
    }
  return d;
}

// The vertex of the face across the edge (u, v) from face f: the opposite of the edge in the other face.
int across(const Topology& t, int f, int u, int v) {
  for (int e = 0; e < t.num_edges(); ++e) {
    const auto a = t.edge_vertices()(e, 0), b = t.edge_vertices()(e, 1);
    if (std::min(u, v) == a && std::max(u, v) == b)
      return t.edge_faces()(e, 0) == f ? t.edge_opposite()(e, 1) : t.edge_opposite()(e, 0);
  }
  return -1;
}

}  // namespace

TEST(Neighbourhood, KRingsAreTheVerticesAtDistanceUpToK) {
  const TriMesh m = sphere_mesh(MeshFamily::MT1, 2);
  const Topology& t = m.topology();
  for (int i : {0, 7, 100, 161}) {
    const std::vector<int> d = distances(t, i);
    for (int k = 0; k <= 4; ++k) {
      const std::vector<int> ring = k_ring(t, i, k);
      std::set<int> expected;
      for (int j = 0; j < t.num_vertices(); ++j)
        if (d[j] >= 1 && d[j] <= k) expected.insert(j);
      EXPECT_EQ(std::set<int>(ring.begin(), ring.end()), expected) << i << " " << k;
      EXPECT_EQ(ring.size(), expected.size()) << "each vertex once";
      // Ordered by ring: distances never decrease along the list.
      for (std::size_t a = 1; a < ring.size(); ++a) EXPECT_LE(d[ring[a - 1]], d[ring[a]]);
    }
    // Ring 1 is the CSR one-ring, counter-clockwise.
    const std::vector<int> one = k_ring(t, i, 1);
    EXPECT_TRUE(std::equal(one.begin(), one.end(), t.ring_vertices().begin() + t.ring_begin(i)));
  }
  // The rings stop growing once the mesh is covered: the icosahedron is covered by 3 rings.
  const TriMesh ico = icosahedron();
  VertexRings r(ico.topology());
  r.start(0);
  EXPECT_EQ(r.grow_to(10), 3);
  EXPECT_EQ(r.vertices().size(), 11u);
  EXPECT_FALSE(r.add_ring());
  EXPECT_THROW(k_ring(t, -1, 1), Error);
  EXPECT_THROW(k_ring(t, t.num_vertices(), 1), Error);
  EXPECT_THROW(k_ring(t, 0, -1), Error);
}

TEST(Neighbourhood, OneObjectVisitsAVertexAgain) {
  // One VertexRings reused from pass to pass (a method keeps one per thread between calls) gives
  // every centre the rings k_ring gives, however often it has started there before.
  const TriMesh m = sphere_mesh(MeshFamily::MT1, 2);
  const Topology& t = m.topology();
  VertexRings r(t);
  for (int pass = 0; pass < 3; ++pass)
    for (int i = 0; i < t.num_vertices(); i += 7) {
      r.start(i);
      r.grow_to(2 + pass % 2);
      EXPECT_EQ(r.vertices(), k_ring(t, i, 2 + pass % 2)) << "pass " << pass << " vertex " << i;
    }
}

TEST(Neighbourhood, OneRingFacesAreTheCounterClockwiseFan) {
  const TriMesh m = sphere_mesh(MeshFamily::MT2, 1);
  const Topology& t = m.topology();
  for (int i = 0; i < t.num_vertices(); ++i) {
    const auto faces = one_ring_faces(t, i);
    ASSERT_EQ(static_cast<int>(faces.size()), t.valence(i));
    for (int k = 0; k < t.valence(i); ++k) {
      const int f = faces[k];
      const int jk = t.ring_vertices()[t.ring_begin(i) + k];
      const int jn = t.ring_vertices()[t.ring_begin(i) + (k + 1) % t.valence(i)];
      // Face k is (i, j_k, j_{k+1}) up to a cyclic shift.
      bool found = false;
      for (int s = 0; s < 3; ++s)
        found = found || (t.faces()(f, s) == i && t.faces()(f, (s + 1) % 3) == jk && t.faces()(f, (s + 2) % 3) == jn);
      EXPECT_TRUE(found) << "vertex " << i << " face " << k;
    }
  }
  EXPECT_THROW(one_ring_faces(t, t.num_vertices()), Error);
}

TEST(Neighbourhood, FacePatchIsTheOneRingOfTheTriangleInOneLoop) {
  const TriMesh m = sphere_mesh(MeshFamily::MT1, 2);  // valences 5 and 6
  const Topology& t = m.topology();
  int regular = 0;
  for (int f = 0; f < t.num_faces(); ++f) {
    const int a = t.faces()(f, 0), b = t.faces()(f, 1), c = t.faces()(f, 2);
    const std::vector<int> patch = face_patch(t, f);
    // Every vertex of every face touching a corner, once.
    std::set<int> expected;
    for (int corner : {a, b, c})
      for (int g : one_ring_faces(t, corner))
        for (int s = 0; s < 3; ++s) expected.insert(t.faces()(g, s));
    EXPECT_EQ(std::set<int>(patch.begin(), patch.end()), expected);
    EXPECT_EQ(patch.size(), expected.size());
    EXPECT_EQ(static_cast<int>(patch.size()), t.valence(a) + t.valence(b) + t.valence(c) - 6);
    if (t.valence(a) == 6 && t.valence(b) == 6 && t.valence(c) == 6) {
      EXPECT_EQ(patch.size(), 12u);
      ++regular;
    }
    // The corners first, then one loop: consecutive outer vertices (cyclically) are joined by an edge,
    // starting across edge (c, a) from f.
    ASSERT_GE(patch.size(), 6u);
    EXPECT_EQ(patch[0], a);
    EXPECT_EQ(patch[1], b);
    EXPECT_EQ(patch[2], c);
    EXPECT_EQ(patch[3], across(t, f, c, a));
    for (std::size_t k = 3; k < patch.size(); ++k) {
      const int next = patch[k + 1 < patch.size() ? k + 1 : 3];
      EXPECT_TRUE(adjacent(t, patch[k], next)) << "face " << f << " position " << k;
    }
    // The loop passes the vertices across (a, b) and (b, c) in that order.
    const auto pos = [&](int v) { return std::find(patch.begin(), patch.end(), v) - patch.begin(); };
    EXPECT_LT(pos(across(t, f, a, b)), pos(across(t, f, b, c)));
  }
  EXPECT_GT(regular, 0);
  EXPECT_THROW(face_patch(t, -1), Error);
  // Low valences: on the octahedron (valence 4) the patch is the whole mesh, 4 + 4 + 4 - 6 = 6.
  const TriMesh octa = octahedron();
  EXPECT_EQ(face_patch(octa.topology(), 0).size(), 6u);
}
