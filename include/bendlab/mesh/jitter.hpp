#pragma once
// Tangential jitter of a unit-sphere mesh: the irregular mesh family (docs/conventions.md §4).
//
// Every node i of the mesh is moved in its tangent plane and projected back onto the sphere:
//   l_i      mean length of the edges at node i, on the mesh before the jitter
//   t1, t2   tangent basis at x_i: t1 = (x_i × a) / |x_i × a|, a the coordinate axis with the
//            smallest |x_i . a| (the first of x, y, z on ties), t2 = x_i × t1
//   phi_i    2 pi u_i, u_i = (g() >> 11) 2^-53 in [0, 1), g a std::mt19937_64 seeded with `seed`
//            and drawn once per node in index order (the engine's output is fixed by the C++
//            standard, the std:: distributions are not, so the meshes are the same everywhere)
//   y_i      x_i + fraction l_i (cos phi_i t1 + sin phi_i t2)  (the direction is uniform in the
//            tangent plane whatever the basis)
//   x_i'     y_i / |y_i|
// Every level of a family is jittered afresh by the same fraction of its own edge lengths, so,
// unlike the Rivara meshes, the irregularity does not fade under refinement.
#include <cstdint>

#include "bendlab/mesh/trimesh.hpp"

namespace bendlab {

/// The fraction of the mean incident edge length by which the irregular family moves each node.
inline constexpr double kDefaultJitterFraction = 0.25;
/// The irregular family's base seed: level k is jittered with seed kDefaultJitterSeed + k.
inline constexpr std::uint64_t kDefaultJitterSeed = 28;

/// Mean length of the edges at each node.
Scalars mean_incident_edge_length(const TriMesh& mesh);

/// The moved nodes y_i above, before the projection. Throws bendlab::Error for a negative or
/// non-finite fraction.
Points jitter_tangential(const TriMesh& sphere, double fraction, std::uint64_t seed);

/// The first triangle of `faces` at positions `x` (nodes on the unit sphere) whose normal does
/// not point outward ((b - a) × (c - a) . (a + b + c) <= 0) or which is degenerate
/// (|(b - a) × (c - a)| <= 1e-12 times its longest edge squared); -1 when there is none.
int first_folded_face(const Faces& faces, const Points& x);

/// The jittered mesh: jitter_tangential projected onto the unit sphere, same faces. Throws
/// bendlab::Error (one line naming the fraction, the seed and a triangle) when the jitter folds a
/// triangle or makes one degenerate.
TriMesh jitter_sphere(const TriMesh& sphere, double fraction, std::uint64_t seed);

}  // namespace bendlab
