#include "bendlab/geometry/point_in_mesh.hpp"

#include <cmath>
#include <numbers>

namespace bendlab {

double winding_number(const Topology& topology, const Points& x, const Vec3& p) {
  const Faces& faces = topology.faces();
  double total = 0;
  for (Eigen::Index f = 0; f < faces.rows(); ++f) {
    const Vec3 a = row(x, faces(f, 0)) - p, b = row(x, faces(f, 1)) - p, c = row(x, faces(f, 2)) - p;
    const double la = a.norm(), lb = b.norm(), lc = c.norm();
    const double num = a.dot(b.cross(c));
    const double den = la * lb * lc + a.dot(b) * lc + b.dot(c) * la + c.dot(a) * lb;
    total += 2.0 * std::atan2(num, den);
  }
  return total / (4.0 * std::numbers::pi);
}

BoundingBox bounding_box(const Points& x) {
  BoundingBox b;
  if (x.rows() == 0) return b;
  b.lo = x.colwise().minCoeff().transpose();
  b.hi = x.colwise().maxCoeff().transpose();
  return b;
}

bool contains(const Topology& topology, const Points& x, const BoundingBox& box, const Vec3& p) {
  return box.contains(p) && winding_number(topology, x, p) > 0.5;
}

}  // namespace bendlab
