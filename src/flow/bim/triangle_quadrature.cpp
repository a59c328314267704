// Built with -fno-math-errno -ffp-contract=fast (CMakeLists.txt), as the rest of the single layer:
// the Gauss-Legendre nodes, found by Newton's iteration, are those of the fused arithmetic.
#include "bendlab/flow/bim/triangle_quadrature.hpp"

#include <fmt/format.h>

#include <cmath>

#include "bendlab/core/types.hpp"

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

}  // namespace bendlab
