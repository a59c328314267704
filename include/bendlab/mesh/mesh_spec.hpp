#pragma once
// Meshes named by a short specification, as the capsule runs take them:
//   "mt1:N", "mt2:N", "octa:N"   the unit-sphere mesh of that family with N triangles
//                                (320, 1280, 5120, ... for MT1/MT2; 512, 2048, ... for octa)
//   "irregular:N"                the irregular family (MT1 jittered, generators.hpp) with N
//                                triangles, default fraction 0.25 and seed 28 + level
//   "inh:mt1", "inh:mt2"         320 triangles and three Rivara passes (the paper's inhomogeneous meshes)
//   anything else                a mesh file (.off, .obj, .ply), read and validated
#include <string>

#include "bendlab/mesh/trimesh.hpp"

namespace bendlab {

/// The mesh of `spec` (see above). Throws bendlab::Error naming the spec for a family without
/// that many triangles, or a file that is missing or refused.
TriMesh mesh_from_spec(const std::string& spec);

}  // namespace bendlab
