// The adaptive rule of the single layer (stokes_single_layer.hpp, quadrature adaptive): clusters
// of consecutive Morton-sorted faces, each with a far rule (one point per face, weights corrected
// to the cluster's moments up to far_order) that a target uses when it is far_ratio radii away.
// Built with -fno-math-errno -ffp-contract=fast (CMakeLists.txt), as the rest of the single layer.
#include <Eigen/QR>
#include <algorithm>
#include <cmath>
#include <limits>

#include "bendlab/flow/bim/stokes_single_layer.hpp"
#include "bendlab/flow/bim/stokeslet_sums.hpp"

namespace bendlab {

namespace {

// The monomials s_x^a s_y^b s_z^c, a + b + c <= order, in a fixed order.
int monomial_count(int order) { return (order + 1) * (order + 2) * (order + 3) / 6; }
void monomials(const Vec3& s, int order, double* out) {
  double px[5], py[5], pz[5];
  px[0] = py[0] = pz[0] = 1;
  for (int k = 1; k <= order; ++k) {
    px[k] = px[k - 1] * s.x();
    py[k] = py[k - 1] * s.y();
    pz[k] = pz[k - 1] * s.z();
  }
  int m = 0;
  for (int a = 0; a <= order; ++a)
    for (int b = 0; a + b <= order; ++b)
      for (int c = 0; a + b + c <= order; ++c) out[m++] = px[a] * py[b] * pz[c];
}

}  // namespace

void StokesSingleLayer::prepare_adaptive(const Points& x) const {
  const int nf = topology_->num_faces();
  const Faces& F = topology_->faces();

  // Clusters: centre, radius, and the far rule's moment-corrected weights.
  const int cs = options_.cluster_size, nc = static_cast<int>(far2_.size());
  const int order = options_.far_order, nm = monomial_count(order);
  const double ratio2 = options_.far_ratio * options_.far_ratio;
#pragma omp parallel for schedule(dynamic, 1)
  for (int c = 0; c < nc; ++c) {
    const int k0 = c * cs, k1 = std::min(nf, k0 + cs), n = k1 - k0;
    Vec3 centre = Vec3::Zero();
    for (int k = k0; k < k1; ++k) centre += Vec3(px_[k], py_[k], pz_[k]);
    centre /= n;
    double rho2 = 0;
    for (int k = k0; k < k1; ++k)
      for (int d = 0; d < 3; ++d) rho2 = std::max(rho2, (row(x, F(slot_[k], d)) - centre).squaredNorm());
    cx_[c] = centre.x(); cy_[c] = centre.y(); cz_[c] = centre.z();
    if (n < nm || !(rho2 > 0)) {  // too few points to match the moments: always the 7-point rule
      far2_[c] = std::numeric_limits<double>::infinity();
      continue;
    }
    far2_[c] = ratio2 * rho2;
    const double inv_rho = 1.0 / std::sqrt(rho2);
    // Residual moments R = sum_k m(s_k) w_k f_k - sum_t m(s_t) W0_t (nm x 3), proxies' V (nm x n).
    Eigen::MatrixXd V(nm, n), R = Eigen::MatrixXd::Zero(nm, 3);
    double m[35];
    for (int k = k0; k < k1; ++k) {
      for (int q = 0; q < 7; ++q) {
        const std::size_t j = 7 * static_cast<std::size_t>(k) + q;
        monomials((Vec3(qx_[j], qy_[j], qz_[j]) - centre) * inv_rho, order, m);
        for (int r = 0; r < nm; ++r) {
          R(r, 0) += m[r] * fx_[j];
          R(r, 1) += m[r] * fy_[j];
          R(r, 2) += m[r] * fz_[j];
        }
      }
      monomials((Vec3(px_[k], py_[k], pz_[k]) - centre) * inv_rho, order, m);
      for (int r = 0; r < nm; ++r) {
        V(r, k - k0) = m[r];
        R(r, 0) -= m[r] * pfx_[k];
        R(r, 1) -= m[r] * pfy_[k];
        R(r, 2) -= m[r] * pfz_[k];
      }
    }
    // Least-norm correction; directions the centroids cannot resolve (a flat cluster has no
    // moments across its plane) are left alone: their source moments vanish to rounding too.
    Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd> cod;
    cod.setThreshold(1e-8);
    cod.compute(V);
    const Eigen::MatrixXd dW = cod.solve(R);
    for (int k = k0; k < k1; ++k) {
      pfx_[k] += dW(k - k0, 0);
      pfy_[k] += dW(k - k0, 1);
      pfz_[k] += dW(k - k0, 2);
    }
  }
}

void StokesSingleLayer::adaptive_sum(double xi, double yi, double zi, double* u) const {
  const int nf = topology_->num_faces();
  const double* qx = qx_.data(); const double* qy = qy_.data(); const double* qz = qz_.data();
  const double* fx = fx_.data(); const double* fy = fy_.data(); const double* fz = fz_.data();
  const double* px = px_.data(); const double* py = py_.data(); const double* pz = pz_.data();
  const double* pfx = pfx_.data(); const double* pfy = pfy_.data(); const double* pfz = pfz_.data();
  const int cs = options_.cluster_size, nc = static_cast<int>(far2_.size());
  double ux = 0, uy = 0, uz = 0, acc[3];
  for (int c = 0; c < nc; ++c) {
    const double dx = cx_[c] - xi, dy = cy_[c] - yi, dz = cz_[c] - zi;
    const int k0 = c * cs, n = std::min(nf, k0 + cs) - k0;
    if (dx * dx + dy * dy + dz * dz >= far2_[c])
      regular_sum(xi, yi, zi, px + k0, py + k0, pz + k0, pfx + k0, pfy + k0, pfz + k0, n, acc);
    else
      regular_sum(xi, yi, zi, qx + 7 * k0, qy + 7 * k0, qz + 7 * k0, fx + 7 * k0, fy + 7 * k0, fz + 7 * k0,
                  7 * n, acc);
    ux += acc[0], uy += acc[1], uz += acc[2];
  }
  u[0] = ux;
  u[1] = uy;
  u[2] = uz;
}

}  // namespace bendlab
