#include "bendlab/flow/lbm/volume_penalty.hpp"

#include <fmt/format.h>

#include <cmath>

namespace bendlab::lbm {

double enclosed_volume(const Faces& faces, const Points& x) {
  double v = 0;
  for (Eigen::Index t = 0; t < faces.rows(); ++t) {
    v += row(x, faces(t, 0)).dot(row(x, faces(t, 1)).cross(row(x, faces(t, 2))));
  }
  return v / 6.0;
}

double add_volume_penalty(const Faces& faces, const Points& x, double kappa_V, double V0, Points& forces) {
  if (!(V0 > 0)) throw Error(fmt::format("volume penalty: reference volume {} must be positive", V0));
  const double V = enclosed_volume(faces, x);
  if (!(V > 0)) throw Error(fmt::format("volume penalty: enclosed volume {} is not positive (inverted mesh?)", V));
  if (forces.rows() != x.rows()) forces = Points::Zero(x.rows(), 3);
  const double s = -kappa_V * (V - V0) / V;
  for (Eigen::Index t = 0; t < faces.rows(); ++t) {
    const Vec3 a = row(x, faces(t, 0)), b = row(x, faces(t, 1)), c = row(x, faces(t, 2));
    const Vec3 An = 0.5 * (b - a).cross(c - a);  // A_t n_t
    for (int v = 0; v < 3; ++v) forces.row(faces(t, v)) += s * An.transpose();
  }
  return 3.0 * kappa_V * (V - V0 - V0 * std::log(V / V0));
}

}  // namespace bendlab::lbm
