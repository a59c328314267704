#include "bendlab/flow/volume_correction.hpp"

#include <fmt/format.h>

#include <cmath>

#include "bendlab/geometry/measures.hpp"

namespace bendlab {

void volume_gradient(const Topology& t, const Points& x, Points& grad) {
  const int nv = t.num_vertices();
  if (grad.rows() != nv) grad.resize(nv, 3);
  const Faces& F = t.faces();
  const auto& rf = t.ring_faces();
  const auto& rc = t.ring_corners();
#pragma omp parallel for schedule(static)
  for (int i = 0; i < nv; ++i) {
    Vec3 g = Vec3::Zero();
    const Vec3 xi = row(x, i);
    for (int r = t.ring_begin(i); r < t.ring_end(i); ++r) {
      const int f = rf[r], c = rc[r];
      g += (row(x, F(f, (c + 1) % 3)) - xi).cross(row(x, F(f, (c + 2) % 3)) - xi);  // 2 A_f n_f
    }
    grad.row(i) = (g / 6.0).transpose();
  }
}

double discrete_flux(const Points& grad, const Points& u) { return grad.cwiseProduct(u).sum(); }

double project_zero_flux(const Points& grad, Points& u) {
  const double q = discrete_flux(grad, u);
  const double a2 = grad.squaredNorm();
  if (!(a2 > 0)) throw Error("volume projection: the volume gradient vanishes");
  u -= (q / a2) * grad;
  return q;
}

double rescale_to_volume(const Topology& t, Points& x, double target_volume) {
  const double v = enclosed_volume(t, x);
  if (!(v > 0) || !(target_volume > 0))
    throw Error(fmt::format("volume rescale: volumes must be positive (current {}, target {})", v, target_volume));
  const double s = std::cbrt(target_volume / v);
  const Eigen::RowVector3d c = volume_centroid(t, x).transpose();
  x.rowwise() -= c;
  x *= s;
  x.rowwise() += c;
  return s;
}

}  // namespace bendlab
