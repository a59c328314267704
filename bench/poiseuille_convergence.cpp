// Poiseuille flow without cells in the slit channel and the tube (shared/spec/CELLS_IN_CHANNELS.md
// section 5): the error of the lattice's steady profile against the exact one, for the
// collisions, tau and walls of flow/lbm/lattice.hpp, over the section's size in dx. One JSON
// document on stdout; scripts/make_poiseuille_doc.py turns it into docs/results/poiseuille.md.
//   ./build/release/poiseuille_convergence [largest tube diameter in dx, default 80]
// Peak velocity 1e-3 (Mach 0.0017): the compressibility error, of order Ma^2, stays below the
// discretisation error at every size. Each case starts from the exact profile and steps until no
// velocity changes by more than 1e-11 of the peak over 200 steps; "steps" says how many it took.
#include <fmt/format.h>

#include <cmath>
#include <cstdlib>
#include <memory>
#include <numbers>
#include <string>
#include <vector>

#include "bendlab/flow/lbm/lattice.hpp"
#include "bendlab/flow/lbm/section_walls.hpp"

using namespace bendlab;
using namespace bendlab::lbm;

namespace {

const char* name(Collision c) {
  switch (c) {
    case Collision::BGK: return "BGK";
    case Collision::Regularized: return "regularized";
    case Collision::TRT: return "TRT";
    default: return "auto";
  }
}

std::int64_t run_to_steady(Lattice& L) {
  std::vector<double> prev(L.num_nodes(), 0.0);
  std::int64_t steps = 0;
  for (; steps < 2000000; steps += 200) {
    L.run(200);
    double change = 0, umax = 0;
    for (std::size_t n = 0; n < L.num_nodes(); ++n) {
      if (L.is_solid(n)) continue;
      const double u = L.velocity(n).x();
      change = std::max(change, std::abs(u - prev[n]));
      umax = std::max(umax, std::abs(u));
      prev[n] = u;
    }
    if (change <= 1e-11 * umax) return steps + 200;
  }
  return -1;
}

// One case: L2 relative error of the profile, relative error of the flow rate (mean velocity).
std::string tube_case(double D, double tau, Collision coll, bool interpolated) {
  const double R = 0.5 * D, nu = (tau - 0.5) / 3.0, umax = 1e-3, g = 4 * nu * umax / (R * R);
  LatticeConfig c;
  c.nx = 1;
  c.ny = c.nz = static_cast<int>(std::ceil(D)) + 2;
  c.tau = tau;
  c.walls = false;
  c.collision = coll;
  c.body_force = Vec3(g, 0, 0);
  c.section = std::make_shared<TubeWall>(R);
  c.interpolated_walls = interpolated;
  Lattice L(c);
  auto exact = [&](const Vec3& x) { return g / (4 * nu) * (R * R - x.y() * x.y() - x.z() * x.z()); };
  L.initialise([&](const Vec3& x) { return Vec3(exact(x), 0, 0); });
  const std::int64_t steps = run_to_steady(L);
  double e2 = 0, u2 = 0, q = 0, emax = 0;
  for (int k = 0; k < c.nz; ++k) {
    for (int j = 0; j < c.ny; ++j) {
      if (L.solid_row(j, k)) continue;
      const Vec3 x = L.position(0, j, k);
      const double u = L.velocity(L.index(0, j, k)).x(), e = u - exact(x);
      e2 += e * e;
      u2 += exact(x) * exact(x);
      emax = std::max(emax, std::abs(e));
      q += u;
    }
  }
  const double q_exact = g * std::numbers::pi * R * R * R * R / (8 * nu);
  return fmt::format(R"({{"geometry": "tube", "size": {}, "tau": {}, "collision": "{}", "walls": "{}", "l2_error": {:.6e}, "max_error": {:.6e}, "flow_rate_error": {:.6e}, "steps": {}}})",
                     D, tau, name(coll), interpolated ? "interpolated" : "staircase", std::sqrt(e2 / u2), emax / umax,
                     q / q_exact - 1, steps);
}

std::string channel_case(int H, double tau, Collision coll) {
  const double nu = (tau - 0.5) / 3.0, umax = 1e-3, g = 8 * nu * umax / (H * H);
  LatticeConfig c;
  c.nx = c.ny = 1;
  c.nz = H;
  c.tau = tau;
  c.walls = true;
  c.collision = coll;
  c.body_force = Vec3(g, 0, 0);
  Lattice L(c);
  auto exact = [&](double z) { return g / (2 * nu) * (0.25 * H * H - z * z); };
  L.initialise([&](const Vec3& x) { return Vec3(exact(x.z()), 0, 0); });
  const std::int64_t steps = run_to_steady(L);
  double e2 = 0, u2 = 0, mean = 0, emax = 0;
  for (int k = 0; k < H; ++k) {
    const double z = L.position(0, 0, k).z(), u = L.velocity(L.index(0, 0, k)).x(), e = u - exact(z);
    e2 += e * e;
    u2 += exact(z) * exact(z);
    emax = std::max(emax, std::abs(e));
    mean += u / H;
  }
  return fmt::format(R"({{"geometry": "channel", "size": {}, "tau": {}, "collision": "{}", "walls": "halfway", "l2_error": {:.6e}, "max_error": {:.6e}, "flow_rate_error": {:.6e}, "steps": {}}})",
                     H, tau, name(coll), std::sqrt(e2 / u2), emax / umax, mean / (g * H * H / (12 * nu)) - 1, steps);
}

}  // namespace

int main(int argc, char** argv) {
  const double largest = argc > 1 ? std::atof(argv[1]) : 80;
  std::vector<std::string> rows;
  for (Collision coll : {Collision::TRT, Collision::BGK, Collision::Regularized}) {
    for (double tau : {0.8, 1.0, 1.5}) {
      for (int H : {10, 20, 40}) rows.push_back(channel_case(H, tau, coll));
    }
  }
  for (double D = 10; D <= largest + 1e-9; D *= 2) {
    for (Collision coll : {Collision::TRT, Collision::BGK}) {
      for (double tau : {0.8, 1.0, 1.5}) rows.push_back(tube_case(D, tau, coll, true));
    }
    rows.push_back(tube_case(D, 1.0, Collision::TRT, false));
    // Between the doublings, where the circle meets the lattice differently.
    if (D * 1.5 <= largest) rows.push_back(tube_case(D * 1.5, 1.0, Collision::TRT, true));
    if (D * 1.5 <= largest) rows.push_back(tube_case(D * 1.5, 1.0, Collision::TRT, false));
  }
  fmt::print("{{\"cases\": [\n");
  for (std::size_t i = 0; i < rows.size(); ++i) fmt::print("  {}{}\n", rows[i], i + 1 < rows.size() ? "," : "");
  fmt::print("]}}\n");
  return 0;
}
