#include "bendlab/elasticity/skalak.hpp"

#include <fmt/format.h>

#include <cmath>

namespace bendlab {

Skalak::Skalak(TopologyPtr topology, const Points& reference, double kS, double C)
    : topology_(std::move(topology)), kS_(kS), C_(C) {
  if (!(kS > 0) || !std::isfinite(kS)) throw Error(fmt::format("Skalak: kS must be positive, got {}", kS));
  if (!(C > -0.5) || !std::isfinite(C))
    throw Error(fmt::format("Skalak: C must be a finite number > -1/2 (area modulus Gs (1 + 2C) > 0), got {}", C));
  flat_triangle_reference(*topology_, reference, "Skalak", a0_, m00_, m01_, m11_);
}

double Skalak::energy(const Points& x) const {
  const Faces& F = topology_->faces();
  const int nf = topology_->num_faces();
  double e = 0;
#pragma omp parallel for reduction(+ : e) schedule(static)
  for (int f = 0; f < nf; ++f) {
    const Vec3 x0 = row(x, F(f, 0));
    const Vec3 e1 = row(x, F(f, 1)) - x0, e2 = row(x, F(f, 2)) - x0;
    const double g00 = e1.dot(e1), g01 = e1.dot(e2), g11 = e2.dot(e2);
    const double I1 = m00_[f] * g00 + 2 * m01_[f] * g01 + m11_[f] * g11 - 2;
    const double I2 = (g00 * g11 - g01 * g01) / (4 * a0_[f] * a0_[f]) - 1;
    e += a0_[f] * (I1 * I1 + 2 * I1 - 2 * I2 + C_ * I2 * I2);
  }
  return kS_ / 12.0 * e;  // Gs/4 = kS/12
}

double Skalak::energy_and_forces(const Points& x, Points& force) const {
  const Topology& t = *topology_;
  const Faces& F = t.faces();
  const int nf = t.num_faces(), nv = t.num_vertices();
  if (force.rows() != nv) force.resize(nv, 3);
  const double c = kS_ / 12.0;
  // Per face: the energy gradient with respect to corners 1 and 2 (corner 0 is minus their sum).
  Points grad1(nf, 3), grad2(nf, 3);
  double e = 0;
#pragma omp parallel for reduction(+ : e) schedule(static)
  for (int f = 0; f < nf; ++f) {
    const Vec3 x0 = row(x, F(f, 0));
    const Vec3 e1 = row(x, F(f, 1)) - x0, e2 = row(x, F(f, 2)) - x0;
    const double g00 = e1.dot(e1), g01 = e1.dot(e2), g11 = e2.dot(e2);
    const double s = 1.0 / (4 * a0_[f] * a0_[f]);
    const double I1 = m00_[f] * g00 + 2 * m01_[f] * g01 + m11_[f] * g11 - 2;
    const double I2 = (g00 * g11 - g01 * g01) * s - 1;
    e += a0_[f] * (I1 * I1 + 2 * I1 - 2 * I2 + C_ * I2 * I2);
    // dW/dI1 = c (2 I1 + 2), dW/dI2 = c (2 C I2 - 2);
    // d I1 / d e1 = 2 (M00 e1 + M01 e2),  d I2 / d e1 = 2 s (g11 e1 - g01 e2),  likewise for e2.
    const double w1 = a0_[f] * c * 2 * (I1 + 1), w2 = a0_[f] * c * 2 * (C_ * I2 - 1);
    const Vec3 d1 = 2 * w1 * (m00_[f] * e1 + m01_[f] * e2) + 2 * s * w2 * (g11 * e1 - g01 * e2);
    const Vec3 d2 = 2 * w1 * (m11_[f] * e2 + m01_[f] * e1) + 2 * s * w2 * (g00 * e2 - g01 * e1);
    grad1.row(f) = d1.transpose();
    grad2.row(f) = d2.transpose();
  }
  gather_corner_gradients(t, grad1, grad2, force);
  return c * e;
}

void Skalak::forces(const Points& x, Points& force) const { energy_and_forces(x, force); }

}  // namespace bendlab
