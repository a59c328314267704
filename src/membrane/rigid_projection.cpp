#include "bendlab/membrane/rigid_projection.hpp"

#include <fmt/format.h>

#include <Eigen/Cholesky>

namespace bendlab {

RigidParts rigid_parts(const Points& x, const Points& F) {
  if (x.rows() != F.rows() || x.rows() == 0)
    throw Error(fmt::format("rigid parts: {} positions and {} forces", x.rows(), F.rows()));
  const Vec3 c = x.colwise().mean().transpose();
  RigidParts p;
  for (Eigen::Index i = 0; i < x.rows(); ++i) {
    const Vec3 f = row(F, i);
    p.force += f;
    p.torque += (row(x, i) - c).cross(f);
  }
  return p;
}

void remove_rigid_motion(const Points& x, Points& F) {
  if (x.rows() != F.rows() || x.rows() == 0)
    throw Error(fmt::format("rigid projection: {} positions and {} forces", x.rows(), F.rows()));
  const auto n = static_cast<double>(x.rows());
  const Vec3 c = x.colwise().mean().transpose();
  // Translations: the mean force off every vertex.
  const Vec3 mean = F.colwise().sum().transpose() / n;
  F.rowwise() -= mean.transpose();
  // Rotations: the torque (about c, unchanged by the step above since sum_i r_i = 0) and the
  // vertices' second moment.
  Vec3 T = Vec3::Zero();
  Mat3 I = Mat3::Zero();
  for (Eigen::Index i = 0; i < x.rows(); ++i) {
    const Vec3 r = row(x, i) - c;
    T += r.cross(row(F, i));
    I += r.squaredNorm() * Mat3::Identity() - r * r.transpose();
  }
  const Eigen::LDLT<Mat3> solve(I);
  if (solve.info() != Eigen::Success || !(solve.vectorD().minCoeff() > 1e-12 * I.trace()))
    throw Error("rigid projection: the vertices lie on one line");
  const Vec3 omega = solve.solve(T);
  for (Eigen::Index i = 0; i < x.rows(); ++i) F.row(i) -= omega.cross(row(x, i) - c).transpose();
}

}  // namespace bendlab
