#include "bendlab/elasticity/neo_hookean.hpp"

#include <fmt/format.h>

#include <cmath>

namespace bendlab {

NeoHookean::NeoHookean(TopologyPtr topology, const Points& reference, double kS)
    : topology_(std::move(topology)), kS_(kS) {
  if (!(kS > 0) || !std::isfinite(kS)) throw Error(fmt::format("neo-Hookean: kS must be positive, got {}", kS));
  flat_triangle_reference(*topology_, reference, "neo-Hookean", a0_, m00_, m01_, m11_);
  for (const double a : a0_) reference_area_ += a;
}

double NeoHookean::energy(const Points& x) const {
  const Faces& F = topology_->faces();
  const int nf = topology_->num_faces();
  double e = 0;
#pragma omp parallel for reduction(+ : e) schedule(static)
  for (int f = 0; f < nf; ++f) {
    const Vec3 x0 = row(x, F(f, 0));
    const Vec3 e1 = row(x, F(f, 1)) - x0, e2 = row(x, F(f, 2)) - x0;
    const double g00 = e1.dot(e1), g01 = e1.dot(e2), g11 = e2.dot(e2);
    const double trC = m00_[f] * g00 + 2 * m01_[f] * g01 + m11_[f] * g11;
    const double detC = (g00 * g11 - g01 * g01) / (4 * a0_[f] * a0_[f]);
    // I1 + 1/(I2+1) - 1 = trC - 2 + 1/detC - 1
    e += a0_[f] * (trC + 1.0 / detC - 3.0);
  }
  return kS_ / 6.0 * e;
}

double NeoHookean::energy_and_forces(const Points& x, Points& force) const {
  const Topology& t = *topology_;
  const Faces& F = t.faces();
  const int nf = t.num_faces(), nv = t.num_vertices();
  if (force.rows() != nv) force.resize(nv, 3);
  const double c = kS_ / 6.0;
  // Per face: the energy gradient with respect to corners 1 and 2 (corner 0 is minus their sum).
  // Allocated per call, so that concurrent calls on one object are safe.
  Points grad1(nf, 3), grad2(nf, 3);
  double e = 0;
#pragma omp parallel for reduction(+ : e) schedule(static)
  for (int f = 0; f < nf; ++f) {
    const Vec3 x0 = row(x, F(f, 0));
    const Vec3 e1 = row(x, F(f, 1)) - x0, e2 = row(x, F(f, 2)) - x0;
    const double g00 = e1.dot(e1), g01 = e1.dot(e2), g11 = e2.dot(e2);
    const double s = 1.0 / (4 * a0_[f] * a0_[f]);
    const double trC = m00_[f] * g00 + 2 * m01_[f] * g01 + m11_[f] * g11;
    const double detC = (g00 * g11 - g01 * g01) * s;
    e += a0_[f] * (trC + 1.0 / detC - 3.0);
    // d trC / d e1 = 2 (M00 e1 + M01 e2),  d detC / d e1 = 2 s (g11 e1 - g01 e2),  likewise for e2;
    // d(1/detC) = -d detC / detC^2.
    const double k = a0_[f] * c, q = 2 * s / (detC * detC);
    const Vec3 d1 = k * (2 * (m00_[f] * e1 + m01_[f] * e2) - q * (g11 * e1 - g01 * e2));
    const Vec3 d2 = k * (2 * (m11_[f] * e2 + m01_[f] * e1) - q * (g00 * e2 - g01 * e1));
    grad1.row(f) = d1.transpose();
    grad2.row(f) = d2.transpose();
  }
  gather_corner_gradients(t, grad1, grad2, force);
  return c * e;
}

void NeoHookean::forces(const Points& x, Points& force) const { energy_and_forces(x, force); }

}  // namespace bendlab
