#include "bendlab/mesh/topology.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cstdint>

namespace bendlab {

namespace {

struct HalfEdge {
  std::int64_t key;  // min * N + max
  int face;
  int corner;        // corner opposite the edge
  bool forward;      // traversed min -> max
};

}  // namespace

std::shared_ptr<const Topology> Topology::build(int num_vertices, const Faces& faces) {
  if (num_vertices <= 0 || faces.rows() == 0)
    throw MeshError(MeshProblem::Empty, fmt::format("{} vertices and {} faces", num_vertices, faces.rows()));
  const int nf = static_cast<int>(faces.rows());
  const std::int64_t nv = num_vertices;

  for (int f = 0; f < nf; ++f)
    for (int k = 0; k < 3; ++k)
      if (faces(f, k) < 0 || faces(f, k) >= num_vertices)
        throw MeshError(MeshProblem::IndexOutOfRange,
                        fmt::format("face {} corner {} refers to vertex {}, but there are {} vertices",
                                    f, k, faces(f, k), num_vertices));
  for (int f = 0; f < nf; ++f)
    if (faces(f, 0) == faces(f, 1) || faces(f, 1) == faces(f, 2) || faces(f, 0) == faces(f, 2))
      throw MeshError(MeshProblem::RepeatedIndex,
                      fmt::format("face {} = ({}, {}, {}) names a vertex twice", f, faces(f, 0),
                                  faces(f, 1), faces(f, 2)));

  // Vertex -> faces (CSR), also detects unreferenced vertices.
  std::vector<int> vf_offsets(num_vertices + 1, 0);
  for (int f = 0; f < nf; ++f)
    for (int k = 0; k < 3; ++k) ++vf_offsets[faces(f, k) + 1];
  for (int i = 0; i < num_vertices; ++i) {
    if (vf_offsets[i + 1] == 0)
      throw MeshError(MeshProblem::UnreferencedVertex, fmt::format("vertex {} belongs to no face", i));
    vf_offsets[i + 1] += vf_offsets[i];
  }
  std::vector<int> vf_faces(vf_offsets.back()), vf_corner(vf_offsets.back());
  {
    std::vector<int> fill(vf_offsets.begin(), vf_offsets.end() - 1);
    for (int f = 0; f < nf; ++f)
      for (int k = 0; k < 3; ++k) {
        const int slot = fill[faces(f, k)]++;
        vf_faces[slot] = f;
        vf_corner[slot] = k;
      }
  }

  // Edges: sort the 3F half-edges by their undirected key.
  std::vector<HalfEdge> half(3 * static_cast<size_t>(nf));
  for (int f = 0; f < nf; ++f)
    for (int k = 0; k < 3; ++k) {
      const int a = faces(f, (k + 1) % 3), b = faces(f, (k + 2) % 3);
      half[3 * f + k] = {std::min(a, b) * nv + std::max(a, b), f, k, a < b};
    }
  std::sort(half.begin(), half.end(), [](const HalfEdge& x, const HalfEdge& y) {
    return x.key != y.key ? x.key < y.key : x.face < y.face;
  });

  auto topo = std::shared_ptr<Topology>(new Topology());
  Topology& t = *topo;
  t.num_vertices_ = num_vertices;
  t.faces_ = faces;
  const int ne = nf * 3 / 2;
  t.edge_vertices_.resize(ne, 2);
  t.edge_faces_.resize(ne, 2);
  t.edge_opposite_.resize(ne, 2);
  t.edge_opposite_corners_.resize(ne, 2);
  t.face_edges_.resize(nf, 3);
  int e = 0;
  for (size_t s = 0; s < half.size();) {
    size_t r = s;
    while (r < half.size() && half[r].key == half[s].key) ++r;
    const int a = static_cast<int>(half[s].key / nv), b = static_cast<int>(half[s].key % nv);
    const size_t count = r - s;
    if (count == 1)
      throw MeshError(MeshProblem::BoundaryEdge,
                      fmt::format("edge ({}, {}) belongs to face {} only: the surface is open", a, b,
                                  half[s].face));
    if (count > 2)
      throw MeshError(MeshProblem::NonManifoldEdge,
                      fmt::format("edge ({}, {}) is shared by {} faces ({}, {}, {}, ...)", a, b, count,
                                  half[s].face, half[s + 1].face, half[s + 2].face));
    const HalfEdge& h0 = half[s].forward ? half[s] : half[s + 1];
    const HalfEdge& h1 = half[s].forward ? half[s + 1] : half[s];
    if (h0.forward == h1.forward)
      throw MeshError(MeshProblem::InconsistentOrientation,
                      fmt::format("faces {} and {} traverse their shared edge ({}, {}) in the same direction",
                                  half[s].face, half[s + 1].face, a, b));
    t.edge_vertices_.row(e) << a, b;
    t.edge_faces_.row(e) << h0.face, h1.face;
    t.edge_opposite_.row(e) << faces(h0.face, h0.corner), faces(h1.face, h1.corner);
    t.edge_opposite_corners_.row(e) << h0.corner, h1.corner;
    t.face_edges_(h0.face, h0.corner) = e;
    t.face_edges_(h1.face, h1.corner) = e;
    ++e;
    s = r;
  }
  // 3F = 2E holds for a closed manifold; any other count was refused above.

  // One-rings: walk the fan i -> a -> b of every vertex.
  t.ring_offsets_ = vf_offsets;
  const size_t total = vf_offsets.back();
  t.ring_vertices_.resize(total);
  t.ring_faces_.resize(total);
  t.ring_edges_.resize(total);
  t.ring_corners_.resize(total);
  for (int i = 0; i < num_vertices; ++i) {
    const int begin = vf_offsets[i], d = vf_offsets[i + 1] - begin;
    int slot = begin;  // current face slot in the vertex's face list
    for (int k = 0; k < d; ++k) {
      const int f = vf_faces[slot], c = vf_corner[slot];
      const int a = faces(f, (c + 1) % 3), b = faces(f, (c + 2) % 3);
      t.ring_vertices_[begin + k] = a;
      t.ring_faces_[begin + k] = f;
      t.ring_corners_[begin + k] = c;
      t.ring_edges_[begin + k] = t.face_edges_(f, (c + 2) % 3);  // edge (i, a) is opposite corner c+2
      // The next face in the fan is the one whose first ring vertex is b.
      int next = -1;
      for (int s2 = begin; s2 < begin + d; ++s2) {
        const int f2 = vf_faces[s2], c2 = vf_corner[s2];
        if (faces(f2, (c2 + 1) % 3) == b) { next = s2; break; }
      }
      if (k + 1 < d && (next < 0 || next == begin))
        throw MeshError(MeshProblem::NonManifoldVertex,
                        fmt::format("the {} faces around vertex {} form more than one fan", d, i));
      slot = next;
    }
    if (slot != begin)
      throw MeshError(MeshProblem::NonManifoldVertex,
                      fmt::format("the {} faces around vertex {} do not close into one fan", d, i));
  }
  return topo;
}

}  // namespace bendlab
