// Built with -fno-math-errno -ffp-contract=fast (CMakeLists.txt), as the rest of the single layer.
#include "bendlab/flow/bim/singular_polar_integral.hpp"

#include <cmath>

namespace bendlab {

// Integral over the triangle (x0, x1, x2), singular at x0, of f(y) . G(y, x0) dS(y), f linear with
// node values f0, f1, f2; polar coordinates about x0 (see the header).
Vec3 singular_polar_integral(const Vec3& x0, const Vec3& x1, const Vec3& x2, const Vec3& f0, const Vec3& f1,
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

}  // namespace bendlab
