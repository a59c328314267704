#pragma once
// Method S (paper section 2.5): the control points of the Loop subdivision patch of every
// triangle, gathered from the CSR one-rings of a Topology (METHOD_S.md section 2, local order in
// loop_shell_basis.hpp).
//
// Admissibility: a triangle may contain at most one extraordinary vertex (valence != 6); that
// vertex becomes the patch's EV corner (u = 1). A mesh with a triangle holding two (the bare
// icosahedron or octahedron, Rivara-refined meshes) is refused: refining it once by Loop
// subdivision makes every triangle admissible.
#include <vector>

#include "bendlab/mesh/topology.hpp"

namespace bendlab::loop_shell {

struct LoopPatches {
  /// Control points of face f: points[offsets[f] .. offsets[f+1]), valence[f] + 6 of them.
  std::vector<int> offsets, points;
  /// Valence N of the patch's EV corner (6 for a regular patch).
  std::vector<int> valence;
  /// The corner (0..2) of faces()(f, .) that is the patch's u = 1 corner; corner + 1 (mod 3) is
  /// v = 1 and corner + 2 is w = 1.
  std::vector<int> corner;

  int num_faces() const { return static_cast<int>(valence.size()); }
  const int* face_points(int f) const { return points.data() + offsets[f]; }

  /// Gathers every face's patch. Throws bendlab::Error naming the first face with two
  /// extraordinary vertices (and telling to refine once), or a vertex whose neighbourhood is too
  /// small for a patch.
  static LoopPatches build(const Topology& topology);
};

}  // namespace bendlab::loop_shell
