#pragma once
// Shapes shared by the bending methods' tests: one fixed, generic rotation (for the invariance
// checks) and the red blood cell of eq. (15) on a mesh of the unit sphere.
#include <Eigen/Geometry>

#include "bendlab/core/types.hpp"
#include "bendlab/mesh/trimesh.hpp"
#include "bendlab/surfaces/analytic_surface.hpp"

namespace bendlab::test_support {

/// A rotation about no coordinate axis (so no symmetry of a test shape hides an error).
inline Mat3 some_rotation() {
  return (Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized()) * Eigen::AngleAxisd(-1.9, Vec3(0, 1, 0)))
      .toRotationMatrix();
}

/// The vertices of `unit_sphere` mapped onto the red blood cell of eq. (15).
inline Points rbc_points(const TriMesh& unit_sphere) {
  return make_rbc()->map_from_unit_sphere(unit_sphere.positions());
}

}  // namespace bendlab::test_support
