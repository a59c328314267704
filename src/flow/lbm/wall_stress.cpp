#include "bendlab/flow/lbm/wall_stress.hpp"

namespace bendlab::lbm {

double wall_shear_stress(const Lattice& lattice) {
  if (!lattice.config().walls) throw Error("wall shear stress: the lattice has no walls at z = -+nz/2");
  const double keep = 1.0 - 0.5 / lattice.config().tau;
  double sum = 0;
  double f[kQ];
  for (const int k : {0, lattice.nz() - 1})
    for (int j = 0; j < lattice.ny(); ++j)
      for (int i = 0; i < lattice.nx(); ++i) {
        const std::size_t node = lattice.index(i, j, k);
        lattice.populations(node, f);
        double rho = 0, pxz = 0;
        for (int q = 0; q < kQ; ++q) {
          rho += f[q];
          pxz += f[q] * kCx[q] * kCz[q];
        }
        const Vec3 u = lattice.velocity(node);
        const double convective = rho * u.x() * u.z();
        sum += -keep * (pxz - convective) - convective;
      }
  return sum / (2.0 * lattice.nx() * lattice.ny());
}

}  // namespace bendlab::lbm
