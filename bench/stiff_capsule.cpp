// The capsule of paper section 4 (eq. (23)) integrated by Cash-Karp or by RKC2 (rkc.hpp), with
// ShearSimulation::velocity as the right-hand side and the volume rescale of the shear driver after
// every accepted step: D_steady (dt-weighted mean of D over gamma t in [5, 10], as `bendlab shear`
// reports it), velocity evaluations, steps and wall time. Not a Google Benchmark: one run per call.
//
//   stiff_capsule TRIANGLES ck|rkc|rkc-stale|run RTOL ATOL [T_END=10] [METHOD=C] [G=0.2] [KB=0.15]
//
// rkc-stale keeps F(y_{n+1}) as the next first stage although the rescale moved y (one evaluation
// fewer per step, as in the experiment of STIFF_STEPPING.md); run calls ShearSimulation::run (the
// library's own Cash-Karp driver), to check that the ck path here is the same computation.
#include <fmt/format.h>

#include <chrono>
#include <ctime>
#include <cstdlib>
#include <memory>
#include <string>

#include "bendlab/bending/bending_method.hpp"
#include "bendlab/flow/capsule_shape.hpp"
#include "bendlab/flow/shear_simulation.hpp"
#include "bendlab/flow/volume_correction.hpp"
#include "bendlab/integrate/cash_karp.hpp"
#include "bendlab/integrate/rkc.hpp"
#include "bendlab/mesh/generators.hpp"

using namespace bendlab;

int main(int argc, char** argv) {
  if (argc < 5) {
    fmt::print(stderr, "usage: {} TRIANGLES ck|rkc|rkc-stale|run RTOL ATOL [T_END=10] [METHOD=C] [G=0.2] [KB=0.15]\n",
               argv[0]);
    return 2;
  }
  const long triangles = std::stol(argv[1]);
  const std::string which = argv[2];
  ShearParameters p;
  p.rtol = std::stod(argv[3]);
  p.atol = std::stod(argv[4]);
  p.t_end = argc > 5 ? std::stod(argv[5]) : 10.0;
  const std::string method = argc > 6 ? argv[6] : "C";
  p.G = argc > 7 ? std::stod(argv[7]) : 0.2;
  p.kappa_b_hat = argc > 8 ? std::stod(argv[8]) : 0.15;
  const TriMesh mesh = sphere_mesh(MeshFamily::MT1, level_with_triangles(MeshFamily::MT1, triangles));
  const auto bending = make_bending_method(method);
  ShearSimulation sim(mesh, p, bending.get());
  const Topology& topo = sim.topology();
  const int n = topo.num_vertices();
  const double w0 = p.t_end >= 10 ? 5.0 : p.t_end / 2, w1 = p.t_end >= 10 ? 10.0 : p.t_end;

  double D_sum = 0, weight = 0, D_last = 0, dt_window = 0;
  std::int64_t window_steps = 0;
  auto record = [&](double t, double dt, double D) {
    D_last = D;
    if (t < w0 || t > w1 + 1e-12) return;
    D_sum += D * dt, weight += dt, dt_window += dt, ++window_steps;
  };

  const auto start = std::chrono::steady_clock::now();
  const std::clock_t cpu_start = std::clock();
  IntegratorStats st;
  RkcStats rs;
  if (which == "run") {
    st = sim.run([&](const ShearSample& s) {
      record(s.time, s.dt, s.D);
      return true;
    });
  } else {
    std::unique_ptr<AdaptiveIntegrator> integrator;
    if (which == "ck") {
      integrator = std::make_unique<CashKarp>(CashKarpOptions{.rtol = p.rtol, .atol = p.atol});
    } else if (which == "rkc" || which == "rkc-stale") {
      RkcOptions o;
      o.rtol = p.rtol;
      o.atol = p.atol;
      o.reuse_f_after_modification = which == "rkc-stale";
      integrator = std::make_unique<Rkc>(o);
    } else {
      fmt::print(stderr, "unknown integrator '{}'\n", which);
      return 2;
    }
    Points xb(n, 3), u(n, 3);
    Eigen::VectorXd y = Eigen::Map<const Eigen::VectorXd>(sim.positions().data(), 3 * n);
    auto rhs = [&](double, const Eigen::VectorXd& state, Eigen::VectorXd& dydt) {
      xb = Eigen::Map<const Points>(state.data(), n, 3);
      sim.velocity(xb, u);
      dydt = Eigen::Map<const Eigen::VectorXd>(u.data(), 3 * n);
    };
    auto on_accept = [&](double t, double dt, Eigen::VectorXd& state) {
      Eigen::Map<Points> xs(state.data(), n, 3);
      xb = xs;
      rescale_to_volume(topo, xb, sim.initial_volume());
      xs = xb;
      record(t, dt, capsule_shape(topo, xb).D);
      return true;
    };
    st = integrator->integrate(rhs, 0.0, p.t_end, y, 0.0, on_accept);
    if (auto* r = dynamic_cast<Rkc*>(integrator.get())) rs = r->stats();
  }
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  fmt::print("triangles {} method {} integrator {} rtol {:g} atol {:g} t_end {:g} | D_steady {:.9f} D_end {:.9f} | "
             "evaluations {} accepted {} rejected {} mean_dt_window {:.4g}",
             mesh.num_faces(), method, which, p.rtol, p.atol, p.t_end, weight > 0 ? D_sum / weight : 0.0, D_last,
             sim.velocity_evaluations(), st.accepted, st.rejected, window_steps ? dt_window / window_steps : 0.0);
  if (which == "rkc" || which == "rkc-stale")
    fmt::print(" | mean_stages {:.1f} max_stages {} rho_max {:.4g} spectral_evals {} estimates {} unconverged {}",
               rs.mean_stages(), rs.max_stages_used, rs.spectral_radius_max, rs.spectral_evaluations,
               rs.spectral_estimates, rs.spectral_unconverged);
  fmt::print(" | wall {:.1f} s cpu {:.1f} s\n", wall, double(std::clock() - cpu_start) / CLOCKS_PER_SEC);
  return 0;
}
