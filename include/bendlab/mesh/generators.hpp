#pragma once
// The mesh families of the paper (docs/conventions.md §4), all on the unit sphere; maps to other
// shapes live with the analytic surfaces (bendlab/surfaces).
//
//   MT1:  icosahedron, k Loop subdivision steps (Loop's rules for the new edge points and for the
//         old vertices), every node projected radially onto the unit sphere after each step.
//   MT2:  icosahedron, k midpoint subdivision steps, projected after each step.
//   Octa: octahedron, k midpoint subdivision steps, projected after each step.
//   Inhomogeneous: a sphere mesh followed by passes of Rivara's longest-edge bisection.
//   Irregular: MT1 at level k with every node jittered tangentially (jitter.hpp) by a fraction
//         (default 0.25) of its mean edge length, seed base + k (default base 28).
// N_T = 20 * 4^k (icosahedron, irregular) or 8 * 4^k (octahedron).
#include <cstdint>
#include <string>

#include "bendlab/mesh/jitter.hpp"
#include "bendlab/mesh/trimesh.hpp"

namespace bendlab {

enum class MeshFamily { MT1, MT2, Octa, Irregular };

/// "mt1", "mt2", "octa", "irregular" (case-insensitive); throws bendlab::Error otherwise.
MeshFamily parse_mesh_family(const std::string& name);
std::string to_string(MeshFamily family);

/// Regular icosahedron (12 vertices, 20 faces) with its vertices on the unit sphere.
TriMesh icosahedron();
/// The same icosahedron rotated so that vertex 0 sits at the north pole (0, 0, 1) and vertex 3 at
/// the south pole (the default places vertices at (+-1, +-phi, 0) / |.|, four of them on the
/// equator z = 0). Same faces; MT1 meshes from it: refine_loop k times.
TriMesh icosahedron_polar();
/// Regular octahedron (6 vertices, 8 faces) with its vertices on the unit sphere.
TriMesh octahedron();

/// One Loop subdivision step (each triangle -> 4; topology, numbering and stencil in
/// subdivision.hpp). New edge point: 3/8 (a + b) + 1/8 (c + d);
/// old vertex of valence n: (1 - n beta) v + beta sum(neighbours), Loop's
/// beta = (5/8 - (3/8 + cos(2 pi / n) / 4)^2) / n. With project, every node is then moved
/// radially onto the unit sphere.
TriMesh refine_loop(const TriMesh& mesh, bool project_to_unit_sphere = true);
/// One midpoint subdivision step (each triangle -> 4), new nodes at edge midpoints, then projected.
TriMesh refine_midpoint(const TriMesh& mesh, bool project_to_unit_sphere = true);
/// One pass of Rivara's longest-edge bisection: every triangle of the mesh as it was at the start
/// of the pass is bisected at its longest edge, with conforming propagation (a neighbour that
/// shares the edge is bisected too, after first bisecting it at its own longest edge when that
/// is another edge). New nodes are projected onto the unit sphere when asked.
/// Edge lengths equal to a relative 1e-12 are ties, broken by the smaller sorted vertex pair, so
/// the result is deterministic; old nodes keep their indices, new nodes are appended. The sphere
/// meshes have many equal edges, and the count after three passes depends on how ties are broken:
/// from the 320-triangle meshes this gives 4880 (MT1) and 3680 (MT2) triangles, the paper 3914 and
/// 3848 (docs/conventions.md §4).
TriMesh rivara_pass(const TriMesh& mesh, bool project_to_unit_sphere = true);

/// The refinement level k whose mesh of `family` has exactly `triangles` triangles
/// (20 * 4^k or 8 * 4^k), or -1 if there is none.
int level_with_triangles(MeshFamily family, long triangles);

/// The limits of sphere_mesh (level 0..8: 1.3 million triangles of MT1; 0..6 Rivara passes), for
/// every caller alike (the command line, the Python module): throws bendlab::Error naming the
/// argument by `level_name` or `rivara_name`.
void check_sphere_mesh_arguments(int level, int rivara_passes, const std::string& level_name = "level",
                                 const std::string& rivara_name = "rivara_passes");

/// The unit sphere of a family at refinement level k, then `rivara_passes` Rivara passes
/// (check_sphere_mesh_arguments first). The irregular family with the default fraction and seed
/// (irregular_sphere_mesh).
TriMesh sphere_mesh(MeshFamily family, int level, int rivara_passes = 0);

/// The irregular family at level k: MT1 of level k, jitter_sphere(mt1, fraction, base_seed + k).
/// Throws bendlab::Error (one line) for a fraction that folds a triangle (jitter.hpp).
TriMesh irregular_sphere_mesh(int level, double fraction = kDefaultJitterFraction,
                              std::uint64_t base_seed = kDefaultJitterSeed);

}  // namespace bendlab
