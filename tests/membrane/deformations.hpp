#pragma once
// Shapes shared by the elastic-law tests (neo-Hookean, Skalak).
#include <Eigen/Geometry>
#include <cmath>

#include "bendlab/core/types.hpp"

namespace bendlab::test {

/// A smooth, non-affine deformation of the unit sphere: stretches in x, shears, bulges.
inline Points deform(const Points& x) {
  Points y = x;
  for (int i = 0; i < x.rows(); ++i) {
    const double a = x(i, 0), b = x(i, 1), c = x(i, 2);
    y(i, 0) = 1.2 * a + 0.1 * c + 0.05 * b * b;
    y(i, 1) = 0.9 * b + 0.08 * a * c;
    y(i, 2) = c + 0.1 * std::sin(2 * a);
  }
  return y;
}

/// Rotation by az about z after ay about y after ax about x.
inline Mat3 rotation(double ax, double ay, double az) {
  return (Eigen::AngleAxisd(az, Vec3::UnitZ()) * Eigen::AngleAxisd(ay, Vec3::UnitY()) *
          Eigen::AngleAxisd(ax, Vec3::UnitX()))
      .toRotationMatrix();
}

}  // namespace bendlab::test
