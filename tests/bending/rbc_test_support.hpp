#pragma once
// The 5120-triangle RBC check shared by the variational methods (C, D): the sign of f against the
// analytic f where the latter is not small, and the errors of eq. (17) for H and f.
#include <cmath>
#include <cstdio>
#include <string>

#include "bendlab/bending/bending_method.hpp"
#include "bendlab/mesh/generators.hpp"
#include "bendlab/surfaces/analytic_surface.hpp"

namespace bendlab::test_support {

struct RbcAgreement {
  double eh_mean = 0, eh_max = 0, ef_mean = 0, ef_max = 0;
  int agree = 0, considered = 0;  ///< nodes where |f_exact| > 10% of max|f|, and those whose f has its sign
  double fraction() const { return double(agree) / considered; }
};

inline RbcAgreement rbc_agreement_5120(const BendingMethod& method, const std::string& label) {
  const TriMesh m = sphere_mesh(MeshFamily::MT1, 4);  // 5120 triangles
  const auto rbc = make_rbc();
  const Points x = rbc->map_from_unit_sphere(m.positions());
  const SurfaceFields exact = rbc->evaluate(x);
  const SurfaceMaxima mx = rbc->maxima();
  const BendingResult r = method.compute(m.topology(), x, 1.0);
  const int n = m.num_vertices();
  RbcAgreement a;
  for (int i = 0; i < n; ++i) {
    const double eh = std::abs(exact.H[i] - r.H[i]) / mx.H;
    const double ef = (exact.f.row(i) - r.force_density.row(i)).norm() / mx.f;
    a.eh_mean += eh / n, a.ef_mean += ef / n;
    a.eh_max = std::max(a.eh_max, eh), a.ef_max = std::max(a.ef_max, ef);
    if (std::abs(exact.f_normal[i]) > 0.1 * mx.f) {
      ++a.considered;
      if (r.force_density.row(i).dot(exact.normal.row(i)) * exact.f_normal[i] > 0) ++a.agree;
    }
  }
  std::printf("[%s RBC 5120] eps_H mean %.4f max %.4f | eps_f mean %.4f max %.4f | sign agrees at %d/%d = %.3f\n",
              label.c_str(), a.eh_mean, a.eh_max, a.ef_mean, a.ef_max, a.agree, a.considered, a.fraction());
  return a;
}

}  // namespace bendlab::test_support
