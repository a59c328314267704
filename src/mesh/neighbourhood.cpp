#include "bendlab/mesh/neighbourhood.hpp"

#include <algorithm>
#include <string>

namespace bendlab {

namespace {

void check_vertex(const Topology& t, int i, const char* what) {
  if (i < 0 || i >= t.num_vertices())
    throw Error(std::string(what) + ": vertex " + std::to_string(i) + " out of range (mesh has " +
                std::to_string(t.num_vertices()) + ")");
}

}  // namespace

void VertexRings::start(int i) {
  check_vertex(t_, i, "VertexRings");
  centre_ = i;
  list_.assign(t_.ring_vertices().begin() + t_.ring_begin(i), t_.ring_vertices().begin() + t_.ring_end(i));
  last_ring_begin_ = 0;
  rings_ = 1;
  stamped_ = false;
}

bool VertexRings::add_ring() {
  if (!stamped_) {  // marks are only needed beyond ring 1, so ring-1 queries never touch them
    if (mark_.empty()) mark_.assign(t_.num_vertices(), 0);
    // A stamp of its own for this start: marks left by an earlier visit of the same centre (the
    // object reused from pass to pass) must not count.
    if (++stamp_ == 0) {
      std::fill(mark_.begin(), mark_.end(), 0u);
      stamp_ = 1;
    }
    mark_[centre_] = stamp_;
    for (int j : list_) mark_[j] = stamp_;
    stamped_ = true;
  }
  const std::size_t end = list_.size();
  for (std::size_t k = last_ring_begin_; k < end; ++k) {
    const int j = list_[k];
    for (int m = t_.ring_begin(j); m < t_.ring_end(j); ++m) {
      const int l = t_.ring_vertices()[m];
      if (mark_[l] != stamp_) {
        mark_[l] = stamp_;
        list_.push_back(l);
      }
    }
  }
  if (list_.size() == end) return false;
  last_ring_begin_ = end;
  ++rings_;
  return true;
}

int VertexRings::grow_to(int k) {
  while (rings_ < k && add_ring()) {
  }
  return rings_;
}

std::vector<int> k_ring(const Topology& topology, int i, int k) {
  check_vertex(topology, i, "k_ring");
  if (k < 0) throw Error("k_ring: number of rings must be >= 0, got " + std::to_string(k));
  if (k == 0) return {};
  VertexRings r(topology);
  r.start(i);
  r.grow_to(k);
  return r.vertices();
}

std::span<const int> one_ring_faces(const Topology& topology, int i) {
  check_vertex(topology, i, "one_ring_faces");
  return std::span<const int>(topology.ring_faces()).subspan(topology.ring_begin(i), topology.valence(i));
}

std::vector<int> face_patch(const Topology& t, int f) {
  if (f < 0 || f >= t.num_faces())
    throw Error("face_patch: face " + std::to_string(f) + " out of range (mesh has " +
                std::to_string(t.num_faces()) + ")");
  const int corner[3] = {t.faces()(f, 0), t.faces()(f, 1), t.faces()(f, 2)};
  // Outer fan of each corner: its one-ring counter-clockwise from the corner after next (c for a)
  // to the next corner (b for a), both excluded. The ring of a holds b, c consecutively (face
  // (a, b, c)), so the fan starts two places after b.
  std::vector<int> loop;
  for (int k = 0; k < 3; ++k) {
    const int v = corner[k], next = corner[(k + 1) % 3];
    const int b = t.ring_begin(v), d = t.valence(v);
    int pos = -1;
    for (int m = 0; m < d; ++m)
      if (t.ring_vertices()[b + m] == next) pos = m;
    for (int m = 2; m < d; ++m) loop.push_back(t.ring_vertices()[b + (pos + m) % d]);
  }
  // Neighbouring fans share the vertex across their common edge; keep each vertex once, first
  // occurrence (only meshes with valence-3 corners repeat more than that).
  std::vector<int> out(corner, corner + 3);
  for (int v : loop)
    if (std::find(out.begin(), out.end(), v) == out.end()) out.push_back(v);
  return out;
}

}  // namespace bendlab
