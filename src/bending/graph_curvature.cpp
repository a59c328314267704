#include "bendlab/bending/graph_curvature.hpp"

#include <cmath>

namespace bendlab {

SecondOrderJet operator+(const SecondOrderJet& a, const SecondOrderJet& b) {
  return {a.f + b.f, a.u + b.u, a.v + b.v, a.uu + b.uu, a.uv + b.uv, a.vv + b.vv};
}

SecondOrderJet operator-(const SecondOrderJet& a, const SecondOrderJet& b) {
  return {a.f - b.f, a.u - b.u, a.v - b.v, a.uu - b.uu, a.uv - b.uv, a.vv - b.vv};
}

SecondOrderJet operator*(const SecondOrderJet& a, const SecondOrderJet& b) {
  // (ab)_x = a_x b + a b_x, (ab)_xy = a_xy b + a_x b_y + a_y b_x + a b_xy.
  return {a.f * b.f,
          a.u * b.f + a.f * b.u,
          a.v * b.f + a.f * b.v,
          a.uu * b.f + 2 * a.u * b.u + a.f * b.uu,
          a.uv * b.f + a.u * b.v + a.v * b.u + a.f * b.uv,
          a.vv * b.f + 2 * a.v * b.v + a.f * b.vv};
}

SecondOrderJet operator*(double c, const SecondOrderJet& a) {
  return {c * a.f, c * a.u, c * a.v, c * a.uu, c * a.uv, c * a.vv};
}

SecondOrderJet operator+(double c, const SecondOrderJet& a) { return {c + a.f, a.u, a.v, a.uu, a.uv, a.vv}; }

SecondOrderJet pow(const SecondOrderJet& a, double e) {
  // phi(a)_x = phi' a_x, phi(a)_xy = phi'' a_x a_y + phi' a_xy with phi = (.)^e.
  const double p0 = std::pow(a.f, e), p1 = e * p0 / a.f, p2 = (e - 1) * p1 / a.f;
  return {p0,
          p1 * a.u,
          p1 * a.v,
          p2 * a.u * a.u + p1 * a.uu,
          p2 * a.u * a.v + p1 * a.uv,
          p2 * a.v * a.v + p1 * a.vv};
}

GraphCurvatures graph_curvatures(const HeightDerivatives& d) {
  // The jets of h_u, h_v, h_uu, h_uv, h_vv: each one's own value, gradient and Hessian.
  const SecondOrderJet p{d.u, d.uu, d.uv, d.uuu, d.uuv, d.uvv};
  const SecondOrderJet q{d.v, d.uv, d.vv, d.uuv, d.uvv, d.vvv};
  const SecondOrderJet r{d.uu, d.uuu, d.uuv, d.uuuu, d.uuuv, d.uuvv};
  const SecondOrderJet s{d.uv, d.uuv, d.uvv, d.uuuv, d.uuvv, d.uvvv};
  const SecondOrderJet t{d.vv, d.uvv, d.vvv, d.uuvv, d.uvvv, d.vvvv};

  const SecondOrderJet w2 = 1.0 + (p * p + q * q);
  const SecondOrderJet n = (1.0 + q * q) * r - 2.0 * (p * q * s) + (1.0 + p * p) * t;
  const SecondOrderJet h = -0.5 * (n * pow(w2, -1.5));

  const double W2 = w2.f, W = std::sqrt(W2);
  GraphCurvatures g;
  g.normal_local = Vec3(-d.u, -d.v, 1.0) / W;
  g.H = h.f;
  g.K = (d.uu * d.vv - d.uv * d.uv) / (W2 * W2);
  // g^ab = delta_ab - h_a h_b / W^2.
  const double g_uu = 1 - d.u * d.u / W2, g_uv = -d.u * d.v / W2, g_vv = 1 - d.v * d.v / W2;
  const double trace_hess_h = g_uu * d.uu + 2 * g_uv * d.uv + g_vv * d.vv;
  const double trace_hess_H = g_uu * h.uu + 2 * g_uv * h.uv + g_vv * h.vv;
  g.lapH = trace_hess_H - trace_hess_h * (d.u * h.u + d.v * h.v) / W2;
  return g;
}

}  // namespace bendlab
