#pragma once
// The D3Q19 velocity set of the immersed-boundary lattice Boltzmann solver (paper section 4.3.2;
// technical note shared/spec/LBM_IBM.md section 1). Lattice units: dx = dt = 1, rho0 = 1,
// c_s^2 = 1/3. Direction 0 rests; the others come in opposite pairs (2k - 1, 2k).
#include <array>

namespace bendlab::lbm {

inline constexpr int kQ = 19;
inline constexpr std::array<int, kQ> kCx = {0, 1, -1, 0, 0, 0, 0, 1, -1, 1, -1, 1, -1, 1, -1, 0, 0, 0, 0};
inline constexpr std::array<int, kQ> kCy = {0, 0, 0, 1, -1, 0, 0, 1, -1, -1, 1, 0, 0, 0, 0, 1, -1, 1, -1};
inline constexpr std::array<int, kQ> kCz = {0, 0, 0, 0, 0, 1, -1, 0, 0, 0, 0, 1, -1, -1, 1, 1, -1, -1, 1};
inline constexpr double kW0 = 1.0 / 3.0, kW1 = 1.0 / 18.0, kW2 = 1.0 / 36.0;
inline constexpr std::array<double, kQ> kW = {kW0, kW1, kW1, kW1, kW1, kW1, kW1, kW2, kW2, kW2,
                                              kW2, kW2, kW2, kW2, kW2, kW2, kW2, kW2, kW2};
/// The index of -c_i.
inline constexpr int opposite(int i) { return i == 0 ? 0 : (i % 2 == 1 ? i + 1 : i - 1); }

/// f_i^eq = w_i rho [1 + 3 c_i.u + 4.5 (c_i.u)^2 - 1.5 u^2]; its moments are rho, rho u and
/// rho/3 I + rho u u.
inline double equilibrium(int i, double rho, double ux, double uy, double uz) {
  const double cu = kCx[i] * ux + kCy[i] * uy + kCz[i] * uz;
  const double uu = ux * ux + uy * uy + uz * uz;
  return kW[i] * rho * (1.0 + 3.0 * cu + 4.5 * cu * cu - 1.5 * uu);
}

}  // namespace bendlab::lbm
