#pragma once
// A snapshot of a solver's bodies (capsule_solver.hpp) in one mesh file: one body is written as
// its membrane's mesh; several as one mesh of all their triangles, with a point field "body"
// (the body's index) to colour them by. The joint topology is built for the write and dropped:
// a run keeps per body positions and forces only.
#include <filesystem>
#include <vector>

#include "bendlab/capsule/capsule_solver.hpp"

namespace bendlab {

/// Writes the bodies at positions x (all bodies' rows) to `path` (mesh_io.hpp's formats).
/// Throws bendlab::Error for rows that do not match the bodies, or a failed write.
void write_bodies_snapshot(const std::filesystem::path& path, const std::vector<SolverBody>& bodies, const Points& x);

}  // namespace bendlab
