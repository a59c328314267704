#include "placement_checks.hpp"

#include <cmath>
#include <numbers>

namespace bendlab::placement_detail {

Mat3 random_rotation(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const double u1 = u(rng), u2 = 2 * std::numbers::pi * u(rng), u3 = 2 * std::numbers::pi * u(rng);
  const Eigen::Quaterniond q(std::sqrt(u1) * std::cos(u3), std::sqrt(1 - u1) * std::sin(u2), std::sqrt(1 - u1) * std::cos(u2),
                             std::sqrt(u1) * std::sin(u3));
  return q.normalized().toRotationMatrix();
}

bool clear_of_wall(const Vessel& v, const Points& x, double clearance) {
  for (Eigen::Index i = 0; i < x.rows(); ++i) {
    if (v.wall_distance(row(x, i)) < clearance) return false;
  }
  return true;
}

bool apart(const Topology& topo, const Candidate& a, const Candidate& b, const Vec3& shift, double clearance,
           const BoundingBox& frame_box, double slack) {
  Points bx = b.x;
  bx.rowwise() += shift.transpose();
  BoundingBox bb{b.box.lo + shift, b.box.hi + shift};
  // Boxes farther apart than the clearance: nothing to check.
  if (((a.box.lo.array() - bb.hi.array()) >= clearance).any() || ((bb.lo.array() - a.box.hi.array()) >= clearance).any()) return true;
  const double c2 = clearance * clearance;
  const Vec3 b_centre = b.centre + shift;
  for (Eigen::Index i = 0; i < a.x.rows(); ++i) {
    const Vec3 p = row(a.x, i);
    if (!bb.contains(p, clearance)) continue;
    const Vec3 q = b.rotation.transpose() * (p - b_centre);
    if (!frame_box.contains(q, clearance + slack)) continue;
    for (Eigen::Index j = 0; j < bx.rows(); ++j) {
      if ((p - row(bx, j)).squaredNorm() < c2) return false;
    }
    if (frame_box.contains(q, slack) && contains(topo, bx, bb, p)) return false;
  }
  for (Eigen::Index j = 0; j < bx.rows(); ++j) {
    const Vec3 p = row(bx, j);
    if (!frame_box.contains(a.rotation.transpose() * (p - a.centre), slack)) continue;
    if (contains(topo, a.x, a.box, p)) return false;
  }
  return true;
}

}  // namespace bendlab::placement_detail
