#include "bendlab/capsule/capsule_shape.hpp"

#include <fmt/format.h>

#include <cmath>
#include <limits>

#include "bendlab/geometry/measures.hpp"

namespace bendlab {

CapsuleShape capsule_shape(const Topology& t, const Points& x) {
  CapsuleShape s;
  s.centroid = volume_centroid(t, x);
  const Faces& F = t.faces();
  Mat3 m = Mat3::Zero();
  double v6 = 0;
  for (int f = 0; f < t.num_faces(); ++f) {
    const Vec3 p0 = row(x, F(f, 0)) - s.centroid, p1 = row(x, F(f, 1)) - s.centroid,
               p2 = row(x, F(f, 2)) - s.centroid;
    const double det = p0.dot(p1.cross(p2));
    const Vec3 sum = p0 + p1 + p2;
    m += (det / 120.0) * (p0 * p0.transpose() + p1 * p1.transpose() + p2 * p2.transpose() + sum * sum.transpose());
    v6 += det;
  }
  s.volume = v6 / 6.0;
  if (!(s.volume > 0)) throw Error(fmt::format("capsule shape: enclosed volume {} is not positive", s.volume));
  s.second_moment = m;
  s.inertia = m.trace() * Mat3::Identity() - m;
  Eigen::SelfAdjointEigenSolver<Mat3> eig(m);  // eigenvalues ascending
  const Vec3 ev = eig.eigenvalues();
  auto half_axis = [&](double mk) { return std::sqrt(std::max(0.0, 5.0 * mk / s.volume)); };
  s.a = half_axis(ev[2]);
  s.b = half_axis(ev[1]);
  s.c = half_axis(ev[0]);
  s.long_axis = eig.eigenvectors().col(2);
  s.short_axis = eig.eigenvectors().col(0);
  s.D = (s.a - s.c) / (s.a + s.c);
  // The eigenvector's sign is arbitrary: fold the angle of its x-z projection into (-pi/2, pi/2].
  double th = std::atan2(s.long_axis.z(), s.long_axis.x());
  if (th > M_PI / 2) th -= M_PI;
  if (th <= -M_PI / 2) th += M_PI;
  s.theta = th;
  return s;
}

double axis_angle(const Vec3& d) {
  double a = std::atan2(d.x(), d.z());
  if (a > M_PI / 2) a -= M_PI;
  if (a <= -M_PI / 2) a += M_PI;
  return a;
}

double shear_plane_phase(const Vec3& p) { return std::atan2(p.x(), p.z()); }

double unwrap_angle(double previous, double raw, double period) {
  return raw + period * std::round((previous - raw) / period);
}

namespace {
// The angle (axis_angle) of the axis of the shear-plane section of the second moment: the
// eigenvector of the 2 x 2 block (x, z) of M with the smaller eigenvalue (short) or the larger.
double section_axis_angle(const Mat3& M, bool short_axis) {
  Eigen::Matrix2d m;
  m << M(0, 0), M(0, 2), M(2, 0), M(2, 2);
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(m);  // ascending
  const Eigen::Vector2d v = eig.eigenvectors().col(short_axis ? 0 : 1);
  return axis_angle(Vec3(v.x(), 0, v.y()));
}
}  // namespace

MotionMarkers motion_markers(const Topology& t, const Points& x0) {
  const CapsuleShape s = capsule_shape(t, x0);
  MotionMarkers m;
  m.short_axis = s.b - s.c > s.a - s.b;
  Vec3 direction = Vec3::UnitX();
  if (s.a - s.c > 1e-9 * s.a) {
    const double alpha = section_axis_angle(s.second_moment, m.short_axis);
    direction = Vec3(std::cos(alpha), 0, -std::sin(alpha));
  }
  double best_value = -std::numeric_limits<double>::infinity();
  for (int i = 0; i < static_cast<int>(x0.rows()); ++i) {
    const double v = (row(x0, i) - s.centroid).dot(direction);
    if (v > best_value + 1e-12 * s.a) {
      best_value = v;
      m.node = i;
    }
  }
  return m;
}

MotionAngles motion_angles(const CapsuleShape& s, const Points& x, const MotionMarkers& m) {
  return {section_axis_angle(s.second_moment, m.short_axis), shear_plane_phase(row(x, m.node) - s.centroid)};
}

}  // namespace bendlab
