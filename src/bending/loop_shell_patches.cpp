#include "bendlab/bending/loop_shell_patches.hpp"

#include <fmt/format.h>

namespace bendlab::loop_shell {

namespace {

// Position of vertex j in the one-ring of i (offset from ring_begin(i)), or -1.
int ring_position(const Topology& t, int i, int j) {
  const auto& ring = t.ring_vertices();
  for (int k = t.ring_begin(i); k < t.ring_end(i); ++k)
    if (ring[k] == j) return k - t.ring_begin(i);
  return -1;
}

// The vertex at (position + offset) mod valence of i's counter-clockwise ring.
int ring_at(const Topology& t, int i, int position) {
  const int d = t.valence(i);
  return t.ring_vertices()[t.ring_begin(i) + ((position % d) + d) % d];
}

}  // namespace

LoopPatches LoopPatches::build(const Topology& t) {
  const Faces& faces = t.faces();
  const int nf = t.num_faces();
  LoopPatches p;
  p.offsets.reserve(nf + 1);
  p.offsets.push_back(0);
  p.valence.reserve(nf);
  p.corner.reserve(nf);
  p.points.reserve(static_cast<size_t>(nf) * 12);
  for (int f = 0; f < nf; ++f) {
    int corner = 0, extraordinary = 0;
    for (int c = 0; c < 3; ++c)
      if (t.valence(faces(f, c)) != 6) {
        if (++extraordinary == 2)
          throw Error(fmt::format(
              "method S: face {} (vertices {}, {}, {}) has two vertices of valence other than 6 ({}, {}, {}); "
              "Loop patches need at most one per face: refine the mesh once",
              f, faces(f, 0), faces(f, 1), faces(f, 2), t.valence(faces(f, 0)), t.valence(faces(f, 1)),
              t.valence(faces(f, 2))));
        corner = c;
      }
    const int ev = faces(f, corner), a = faces(f, (corner + 1) % 3), b = faces(f, (corner + 2) % 3);
    const int n = t.valence(ev);
    auto fail = [&](const char* what) {
      return Error(fmt::format("method S: face {} has no Loop patch: {} (vertices {}, {}, {})", f, what, ev, a, b));
    };
    if (n < 3) throw fail("a vertex has fewer than 3 neighbours");
    std::vector<int> local(n + 6, -1);
    local[0] = ev;
    // EV's ring: A at position k, B at k + 1 (face (EV, A, B) is counter-clockwise); local
    // m = 1..N is the ring read clockwise from A.
    const int k = ring_position(t, ev, a);
    if (k < 0 || ring_at(t, ev, k + 1) != b) throw fail("inconsistent one-ring");
    for (int m = 1; m <= n; ++m) local[m] = ring_at(t, ev, k - (m - 1));
    // A's ring counter-clockwise: EV, 2, N+3, N+2, N+1, B.
    const int pa = ring_position(t, a, ev);
    if (pa < 0 || ring_at(t, a, pa + 1) != local[2] || ring_at(t, a, pa + 5) != b)
      throw fail("the ring of the v = 1 corner is not regular");
    local[n + 3] = ring_at(t, a, pa + 2);
    local[n + 2] = ring_at(t, a, pa + 3);
    local[n + 1] = ring_at(t, a, pa + 4);
    // B's ring counter-clockwise: EV, A, N+1, N+4, N+5, N-1.
    const int pb = ring_position(t, b, ev);
    if (pb < 0 || ring_at(t, b, pb + 1) != a || ring_at(t, b, pb + 2) != local[n + 1] ||
        ring_at(t, b, pb + 5) != local[n - 1])
      throw fail("the ring of the w = 1 corner is not regular");
    local[n + 4] = ring_at(t, b, pb + 3);
    local[n + 5] = ring_at(t, b, pb + 4);
    p.points.insert(p.points.end(), local.begin(), local.end());
    p.offsets.push_back(static_cast<int>(p.points.size()));
    p.valence.push_back(n);
    p.corner.push_back(corner);
  }
  return p;
}

}  // namespace bendlab::loop_shell
