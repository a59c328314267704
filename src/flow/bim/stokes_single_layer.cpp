#include "bendlab/flow/bim/stokes_single_layer.hpp"

#include <fmt/format.h>

#include <array>
#include <cmath>

namespace bendlab {

const TriangleRule7& triangle_rule7() {
  static const TriangleRule7 rule = [] {
    // Strang & Fix / Dunavant degree 5: centroid plus two orbits of three points.
    const double s15 = std::sqrt(15.0);
    const double a1 = (9.0 - 2.0 * s15) / 21.0, b1 = (6.0 + s15) / 21.0;
    const double a2 = (9.0 + 2.0 * s15) / 21.0, b2 = (6.0 - s15) / 21.0;
    const double w1 = (155.0 + s15) / 1200.0, w2 = (155.0 - s15) / 1200.0;
    TriangleRule7 r{};
    const double pts[7][3] = {{1.0 / 3, 1.0 / 3, 1.0 / 3}, {a1, b1, b1}, {b1, a1, b1}, {b1, b1, a1},
                              {a2, b2, b2},               {b2, a2, b2}, {b2, b2, a2}};
    const double w[7] = {9.0 / 40.0, w1, w1, w1, w2, w2, w2};
    for (int q = 0; q < 7; ++q) {
      for (int k = 0; k < 3; ++k) r.bary[q][k] = pts[q][k];
      r.weight[q] = w[q];
    }
    return r;
  }();
  return rule;
}

void gauss_legendre_unit(int n, std::vector<double>& nodes, std::vector<double>& weights) {
  if (n < 1) throw Error(fmt::format("Gauss-Legendre: need at least one point, got {}", n));
  nodes.assign(n, 0.0);
  weights.assign(n, 0.0);
  for (int i = 0; i < n; ++i) {
    // Newton on P_n from the Chebyshev-like initial guess; then map [-1, 1] -> [0, 1].
    double z = std::cos(M_PI * (i + 0.75) / (n + 0.5)), dp = 0;
    for (int it = 0; it < 100; ++it) {
      double p0 = 1, p1 = z;
      for (int k = 2; k <= n; ++k) {
        const double p2 = ((2 * k - 1) * z * p1 - (k - 1) * p0) / k;
        p0 = p1;
        p1 = p2;
      }
      dp = n * (z * p1 - p0) / (z * z - 1);
      const double dz = p1 / dp;
      z -= dz;
      if (std::abs(dz) < 1e-16) break;
    }
    {  // derivative at the converged node
      double p0 = 1, p1 = z;
      for (int k = 2; k <= n; ++k) {
        const double p2 = ((2 * k - 1) * z * p1 - (k - 1) * p0) / k;
        p0 = p1;
        p1 = p2;
      }
      dp = n * (z * p1 - p0) / (z * z - 1);
    }
    nodes[i] = 0.5 * (1 - z);
    weights[i] = 1.0 / ((1 - z * z) * dp * dp);  // 2 / ((1 - z^2) P'^2), halved for [0, 1]
  }
}

StokesSingleLayer::StokesSingleLayer(TopologyPtr topology, SingleLayerOptions options)
    : topology_(std::move(topology)), options_(options) {
  if (options_.angular_subdivisions < 1)
    throw Error(fmt::format("single layer: angular_subdivisions must be >= 1, got {}", options_.angular_subdivisions));
  gauss_legendre_unit(options_.angular_points, gl_nodes_, gl_weights_);
  const std::size_t nq = 7 * static_cast<std::size_t>(topology_->num_faces());
  for (auto* v : {&qx_, &qy_, &qz_, &fx_, &fy_, &fz_}) v->assign(nq, 0.0);
}

namespace {

// Integral over the triangle (x0, x1, x2), singular at x0, of f(y) . G(y, x0) dS(y), f linear with
// node values f0, f1, f2; polar coordinates about x0 (see the header).
Vec3 polar_integral(const Vec3& x0, const Vec3& x1, const Vec3& x2, const Vec3& f0, const Vec3& f1,
                    const Vec3& f2, int subdivisions, const std::vector<double>& nodes,
                    const std::vector<double>& weights) {
  const Vec3 a = x1 - x0, b = x2 - x0;
  const double la = a.norm();
  const Vec3 t1 = a / la;
  Vec3 t2 = b - b.dot(t1) * t1;
  t2.normalize();
  // 2D coordinates in the plane: x1 -> (la, 0), x2 -> (bx, by) with by > 0.
  const double bx = b.dot(t1), by = b.dot(t2);
  const double alpha = std::atan2(by, bx);  // corner angle at x0, in (0, pi)
  const double dx = bx - la, dy = by;       // edge x1 -> x2
  Vec3 sum = Vec3::Zero();
  const double h = alpha / subdivisions;
  for (int s = 0; s < subdivisions; ++s) {
    for (std::size_t q = 0; q < nodes.size(); ++q) {
      const double phi = h * (s + nodes[q]);
      const double c = std::cos(phi), sn = std::sin(phi);
      // The ray x0 + rho (c, sn) meets the edge x1 + v (x2 - x1) at
      // rho = (a x d) / (e x d), v = -(e x a) / (e x d) (2D cross products).
      const double exd = c * dy - sn * dx;
      const double rho = (la * dy) / exd;
      const double v = (sn * la) / exd;
      const Vec3 e = c * t1 + sn * t2;
      const Vec3 fm = f0 + f1 + v * (f2 - f1);  // f(x0) + f(edge point)
      sum += (weights[q] * h * 0.5 * rho) * (fm + e.dot(fm) * e);
    }
  }
  return sum;
}

// Sum over all quadrature points y_k of the Stokeslet G(y_k, x) . f_k w_k for one target x.
// Compiled three times (AVX-512, AVX2+FMA and baseline x86-64) and picked at run time, so the
// same binary runs everywhere and uses 8- or 4-wide doubles where the processor has them. The
// file is built with -fno-math-errno (so that sqrt vectorises) and -ffp-contract=fast (FMA).
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__) && !defined(__SANITIZE_ADDRESS__)
__attribute__((target_clones("avx512f", "avx2,fma", "default")))
#endif
void regular_sum(double xi, double yi, double zi, const double* __restrict qx, const double* __restrict qy,
                 const double* __restrict qz, const double* __restrict fx, const double* __restrict fy,
                 const double* __restrict fz, int nq, double* out) {
  double ux = 0, uy = 0, uz = 0;
#pragma omp simd reduction(+ : ux, uy, uz)
  for (int k = 0; k < nq; ++k) {
    const double dx = qx[k] - xi, dy = qy[k] - yi, dz = qz[k] - zi;
    const double s = 1.0 / std::sqrt(dx * dx + dy * dy + dz * dz);
    const double fr = (fx[k] * dx + fy[k] * dy + fz[k] * dz) * s * s * s;
    ux += fx[k] * s + dx * fr;
    uy += fy[k] * s + dy * fr;
    uz += fz[k] * s + dz * fr;
  }
  out[0] = ux;
  out[1] = uy;
  out[2] = uz;
}

}  // namespace

void StokesSingleLayer::velocity(const Points& x, const Points& f, double mu, Points& u) const {
  const Topology& t = *topology_;
  const int nv = t.num_vertices(), nf = t.num_faces();
  if (x.rows() != nv || f.rows() != nv)
    throw Error(fmt::format("single layer: {} positions and {} densities for {} vertices", x.rows(), f.rows(), nv));
  if (u.rows() != nv) u.resize(nv, 3);
  const Faces& F = t.faces();
  const TriangleRule7& rule = triangle_rule7();

#pragma omp parallel for schedule(static)
  for (int tf = 0; tf < nf; ++tf) {
    const Vec3 x0 = row(x, F(tf, 0)), x1 = row(x, F(tf, 1)), x2 = row(x, F(tf, 2));
    const Vec3 f0 = row(f, F(tf, 0)), f1 = row(f, F(tf, 1)), f2 = row(f, F(tf, 2));
    const double area = 0.5 * (x1 - x0).cross(x2 - x0).norm();
    for (int q = 0; q < 7; ++q) {
      const double* l = rule.bary[q];
      const Vec3 y = l[0] * x0 + l[1] * x1 + l[2] * x2;
      const Vec3 fw = (rule.weight[q] * area) * (l[0] * f0 + l[1] * f1 + l[2] * f2);
      const std::size_t k = 7 * static_cast<std::size_t>(tf) + q;
      qx_[k] = y.x(); qy_[k] = y.y(); qz_[k] = y.z();
      fx_[k] = fw.x(); fy_[k] = fw.y(); fz_[k] = fw.z();
    }
  }

  const int nq = 7 * nf;
  const double* qx = qx_.data(); const double* qy = qy_.data(); const double* qz = qz_.data();
  const double* fx = fx_.data(); const double* fy = fy_.data(); const double* fz = fz_.data();
  const auto& rf = t.ring_faces();
  const auto& rc = t.ring_corners();
  const double scale = 1.0 / (8.0 * M_PI * mu);

#pragma omp parallel for schedule(static)
  for (int i = 0; i < nv; ++i) {
    const double xi = x(i, 0), yi = x(i, 1), zi = x(i, 2);
    // Regular rule over every triangle (the hot loop: 7 F kernel evaluations per target).
    double acc[3];
    regular_sum(xi, yi, zi, qx, qy, qz, fx, fy, fz, nq, acc);
    const double ux = acc[0], uy = acc[1], uz = acc[2];
    // The triangles at node i: take back what the regular rule added, add the polar integral.
    Vec3 corr = Vec3::Zero();
    const Vec3 xv(xi, yi, zi);
    for (int r = t.ring_begin(i); r < t.ring_end(i); ++r) {
      const int tf = rf[r], c = rc[r];
      for (int q = 0; q < 7; ++q) {
        const int k = 7 * tf + q;
        const Vec3 d(qx[k] - xi, qy[k] - yi, qz[k] - zi), fw(fx[k], fy[k], fz[k]);
        const double s = 1.0 / d.norm();
        corr -= fw * s + d * (fw.dot(d) * s * s * s);
      }
      const int j = F(tf, (c + 1) % 3), l = F(tf, (c + 2) % 3);
      corr += polar_integral(xv, row(x, j), row(x, l), row(f, i), row(f, j), row(f, l),
                             options_.angular_subdivisions, gl_nodes_, gl_weights_);
    }
    u(i, 0) = scale * (ux + corr.x());
    u(i, 1) = scale * (uy + corr.y());
    u(i, 2) = scale * (uz + corr.z());
  }
}

}  // namespace bendlab
