// The lattice Boltzmann fluid step (D3Q19, AA pattern, structure of arrays) against the memory
// bandwidth of the same machine, measured in the same program.
//   ./build/release/bench_lbm
//
// Benchmarks (last argument: OpenMP threads):
//   BM_StreamCopy, BM_StreamTriad  STREAM-like a = b and a = b + s c over 2^24 doubles per array.
//                  bytes_per_second counts STREAM's bytes (16 and 24 per element); the counter
//                  traffic_GBps adds the write-allocate line fill of the target (24 and 32 bytes),
//                  the traffic the memory actually sees.
//   BM_LbmStep/<collision>  one step of a 128^3 box between moving walls (shear flow, force field
//                  read but zero). MLUPS = node updates per microsecond; GBps = MLUPS x 328 bytes
//                  (19 + 19 doubles of populations and 3 force components per node update; the AA
//                  pattern writes back to the lines it read, so no write-allocate traffic);
//                  bound_fraction = GBps / (the triad's traffic_GBps on as many threads), the
//                  fraction of the bandwidth bound of this layout that the kernel reaches.
//   BM_LbmStep<collision>Unpadded  the same with the slots num_nodes() apart (pad_slots = false),
//                  the plain layout the padded one is measured against.
//   BM_LbmStepTRTPeriodic/<threads>  one TRT step of a wall-free (fully periodic) 128^3 box with a
//                  body force: the reference of the channel and tube lattices.
//   BM_LbmStepTube/<threads>  one TRT step of the tube of HemoCell's pipeflow example (25 um across,
//                  50 um long at dx = 0.5 um: D = 50 dx, 100 x 54 x 54 nodes) driven by a body
//                  force, with the interpolated bounce-back of its circular wall. MLUPS counts fluid
//                  nodes only; its ratio to BM_LbmStepTRTPeriodic's on as many threads is the
//                  wall cost (target: at least 0.7; scripts/make_lbm_performance_doc.py).
//   BM_LbmStepTubePlainWalls/<threads>  the same tube with plain halfway bounce-back (no
//                  interpolation pass): what the interpolated wall costs on top.
//   BM_MembraneIbm/<threads>  the capsule's part of one IB-LBM step in the paper's full-size case:
//                  5120 triangles (2562 nodes) of R = 13.5 dx centred in the same 128^3 box,
//                  neo-Hookean + bending (method A, ESPResSo's tribend) + ESPResSo's volume force,
//                  then spread, interpolate and move (phi2), as LbmCapsuleSolver::step does without
//                  the fluid step. fraction_of_fluid_step = its time over BM_LbmStepBGK's per step
//                  on as many threads (registered, hence run, before it).
#include <benchmark/benchmark.h>
#include <omp.h>

#include <algorithm>
#include <map>
#include <utility>
#include <memory>
#include <vector>

#include "bendlab/bending/bending_method.hpp"
#include "bendlab/flow/lbm/immersed_boundary.hpp"
#include "bendlab/flow/lbm/lattice.hpp"
#include "bendlab/flow/lbm/section_walls.hpp"
#include "bendlab/membrane/espresso_volume_force.hpp"
#include "bendlab/membrane/membrane_model.hpp"
#include "bendlab/mesh/generators.hpp"

using namespace bendlab;
using namespace bendlab::lbm;

namespace {

constexpr std::size_t kStreamN = std::size_t{1} << 24;
constexpr double kBytesPerUpdate = 328.0;
std::map<int, double> triad_traffic;  // threads -> GB/s including write-allocate
std::map<int, double> bgk_step_seconds;  // threads -> seconds per BGK fluid step of the 128^3 box

struct StreamArrays {
  std::vector<double> a, b, c;
  StreamArrays() : a(kStreamN), b(kStreamN), c(kStreamN) {
    const auto n = static_cast<std::int64_t>(kStreamN);
#pragma omp parallel for schedule(static)
    for (std::int64_t i = 0; i < n; ++i) {  // first touch by the threads that use them
      a[i] = 0.0;
      b[i] = 1.0;
      c[i] = 2.0;
    }
  }
};
StreamArrays& stream_arrays() {
  static StreamArrays s;
  return s;
}

void BM_StreamCopy(benchmark::State& state) {
  omp_set_num_threads(static_cast<int>(state.range(0)));
  auto& s = stream_arrays();
  double* a = s.a.data();
  const double* b = s.b.data();
  const auto n = static_cast<std::int64_t>(kStreamN);
  for (auto _ : state) {
#pragma omp parallel for schedule(static)
    for (std::int64_t i = 0; i < n; ++i) a[i] = b[i];
    benchmark::ClobberMemory();
  }
  state.SetBytesProcessed(state.iterations() * static_cast<std::int64_t>(16 * kStreamN));
  state.counters["traffic_GBps"] = benchmark::Counter(static_cast<double>(state.iterations()) * 24.0 * kStreamN * 1e-9, benchmark::Counter::kIsRate);
}
BENCHMARK(BM_StreamCopy)->Arg(1)->Arg(2)->UseRealTime()->Unit(benchmark::kMillisecond);

void BM_StreamTriad(benchmark::State& state) {
  const int threads = static_cast<int>(state.range(0));
  omp_set_num_threads(threads);
  auto& s = stream_arrays();
  double* a = s.a.data();
  const double* b = s.b.data();
  const double* c = s.c.data();
  const auto n = static_cast<std::int64_t>(kStreamN);
  const double scalar = 3.0;
  for (auto _ : state) {
#pragma omp parallel for schedule(static)
    for (std::int64_t i = 0; i < n; ++i) a[i] = b[i] + scalar * c[i];
    benchmark::ClobberMemory();
  }
  state.SetBytesProcessed(state.iterations() * static_cast<std::int64_t>(24 * kStreamN));
  state.counters["traffic_GBps"] = benchmark::Counter(static_cast<double>(state.iterations()) * 32.0 * kStreamN * 1e-9, benchmark::Counter::kIsRate);
}
BENCHMARK(BM_StreamTriad)->Arg(1)->Arg(2)->UseRealTime()->Unit(benchmark::kMillisecond);

Lattice& shear_box(Collision collision, bool padded = true) {
  static std::map<std::pair<Collision, bool>, std::unique_ptr<Lattice>> cache;
  const std::pair key(collision, padded);
  if (!cache[key]) {
    cache.clear();  // one 128^3 lattice (about 370 MB) at a time
    LatticeConfig c;
    c.nx = c.ny = c.nz = 128;
    c.tau = collision == Collision::BGK ? 1.0 : 0.8;
    c.collision = collision;
    c.wall_velocity = 0.01;
    c.pad_slots = padded;
    cache[key] = std::make_unique<Lattice>(c);
    cache[key]->initialise_shear_flow();
  }
  return *cache[key];
}

void lbm_step(benchmark::State& state, Collision collision, bool padded = true) {
  const int threads = static_cast<int>(state.range(0));
  omp_set_num_threads(threads);
  Lattice& L = shear_box(collision, padded);
  L.run(2);  // warm up both parities
  for (auto _ : state) L.step();
  const double updates = static_cast<double>(state.iterations()) * static_cast<double>(L.num_nodes());
  state.counters["MLUPS"] = benchmark::Counter(updates * 1e-6, benchmark::Counter::kIsRate);
  state.counters["GBps"] = benchmark::Counter(updates * kBytesPerUpdate * 1e-9, benchmark::Counter::kIsRate);
  // Filled in by the triad run on as many threads (registered, hence run, before this one).
  if (triad_traffic.count(threads) && state.iterations() > 0) {
    state.counters["bound_fraction"] = benchmark::Counter(updates * kBytesPerUpdate * 1e-9 / triad_traffic[threads], benchmark::Counter::kIsRate);
  }
}
void BM_LbmStepBGK(benchmark::State& state) {
  const double t0 = omp_get_wtime();
  lbm_step(state, Collision::BGK);  // includes two warm-up steps
  if (state.iterations() > 0)
    bgk_step_seconds[static_cast<int>(state.range(0))] = (omp_get_wtime() - t0) / static_cast<double>(state.iterations() + 2);
}

// The membrane and IBM part of one step at 5120 triangles, R = 13.5, in the 128^3 box.
void BM_MembraneIbm(benchmark::State& state) {
  const int threads = static_cast<int>(state.range(0));
  omp_set_num_threads(threads);
  Lattice& L = shear_box(Collision::BGK);
  const double R = 13.5, G = 0.05, kB_hat = 0.0375;
  MembraneParameters p;
  p.kS = 1.0 / G;  // shear units, as LbmCapsuleSolver uses them
  p.kB = kB_hat / G;
  p.bending = make_bending_method("A");
  p.volume_force = std::make_shared<const EspressoVolumeForce>(EspressoVolumeForce::for_membrane(p.kS));
  const TriMesh mesh = sphere_mesh(MeshFamily::MT1, 4);  // 5120 triangles
  const MembraneModel membrane(mesh, p);
  Points x = mesh.positions(), X, F, U;
  x.col(0) *= 1.1;  // a deformed shape: every force is non-zero
  x.col(2) /= 1.1;
  const double scale = L.viscosity() * L.shear_rate() * R * R;
  for (auto _ : state) {
    membrane.forces(x, F);
    F *= scale;
    X = R * x;
    L.clear_force();
    spread_forces(L, X, F, IbKernel::Phi2);
    interpolate_velocity(L, X, U, IbKernel::Phi2);
    euler_move(X, U);
    benchmark::DoNotOptimize(X.data());
  }
  state.counters["triangles"] = static_cast<double>(mesh.num_faces());
  if (bgk_step_seconds.count(threads) && state.iterations() > 0)
    state.counters["fraction_of_fluid_step"] =
        benchmark::Counter(bgk_step_seconds[threads] * static_cast<double>(state.iterations()),
                           benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}
void BM_LbmStepRegularized(benchmark::State& state) { lbm_step(state, Collision::Regularized); }
// The same steps with the slots num_nodes() apart (LatticeConfig::pad_slots = false), the layout
// the padding replaced: 128^3 puts the 41 streams of a row a power of two apart.
void BM_LbmStepBGKUnpadded(benchmark::State& state) { lbm_step(state, Collision::BGK, false); }
void BM_LbmStepRegularizedUnpadded(benchmark::State& state) { lbm_step(state, Collision::Regularized, false); }

void BM_LbmStepTRTPeriodic(benchmark::State& state) {
  const int threads = static_cast<int>(state.range(0));
  omp_set_num_threads(threads);
  LatticeConfig c;
  c.nx = c.ny = c.nz = 128;
  c.tau = 0.9;
  c.walls = false;
  c.collision = Collision::TRT;
  c.body_force = Vec3(1e-7, 0, 0);
  Lattice L(c);
  L.run(2);
  for (auto _ : state) L.step();
  const double updates = static_cast<double>(state.iterations()) * static_cast<double>(L.num_fluid_nodes());
  state.counters["MLUPS"] = benchmark::Counter(updates * 1e-6, benchmark::Counter::kIsRate);
  if (triad_traffic.count(threads) && state.iterations() > 0) {
    state.counters["bound_fraction"] = benchmark::Counter(updates * kBytesPerUpdate * 1e-9 / triad_traffic[threads], benchmark::Counter::kIsRate);
  }
}

void lbm_step_tube(benchmark::State& state, bool interpolated) {
  const int threads = static_cast<int>(state.range(0));
  omp_set_num_threads(threads);
  LatticeConfig c;
  c.nx = 100;
  c.ny = c.nz = 54;  // 50 dx and two solid layers on either side (FlowUnits)
  c.tau = 0.9;
  c.walls = false;
  c.collision = Collision::TRT;
  c.body_force = Vec3(1e-7, 0, 0);
  c.section = std::make_shared<TubeWall>(25.0);
  c.interpolated_walls = interpolated;
  Lattice L(c);
  L.run(2);
  for (auto _ : state) L.step();
  const double updates = static_cast<double>(state.iterations()) * static_cast<double>(L.num_fluid_nodes());
  state.counters["MLUPS"] = benchmark::Counter(updates * 1e-6, benchmark::Counter::kIsRate);
  state.counters["fluid_nodes"] = static_cast<double>(L.num_fluid_nodes());
  state.counters["wall_link_rows"] = static_cast<double>(L.num_wall_links());
}

void BM_LbmStepTube(benchmark::State& state) { lbm_step_tube(state, true); }
void BM_LbmStepTubePlainWalls(benchmark::State& state) { lbm_step_tube(state, false); }

// Measures the triad once per thread count for bound_fraction (not reported by itself).
void BM_TriadReference(benchmark::State& state) {
  const int threads = static_cast<int>(state.range(0));
  omp_set_num_threads(threads);
  auto& s = stream_arrays();
  double* a = s.a.data();
  const double* b = s.b.data();
  const double* c = s.c.data();
  const auto n = static_cast<std::int64_t>(kStreamN);
  double best = 0;
  for (auto _ : state) {
    for (int rep = 0; rep < 5; ++rep) {
      const double t0 = omp_get_wtime();
#pragma omp parallel for schedule(static)
      for (std::int64_t i = 0; i < n; ++i) a[i] = b[i] + 3.0 * c[i];
      benchmark::ClobberMemory();
      best = std::max(best, 32.0 * kStreamN * 1e-9 / (omp_get_wtime() - t0));
    }
  }
  triad_traffic[threads] = best;
  state.counters["best_traffic_GBps"] = best;
}
BENCHMARK(BM_TriadReference)->Arg(1)->Arg(2)->Iterations(1)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_LbmStepBGK)->Arg(1)->Arg(2)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_LbmStepRegularized)->Arg(1)->Arg(2)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_LbmStepBGKUnpadded)->Arg(1)->Arg(2)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_LbmStepRegularizedUnpadded)->Arg(1)->Arg(2)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_MembraneIbm)->Arg(1)->Arg(2)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_LbmStepTRTPeriodic)->Arg(1)->Arg(2)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_LbmStepTube)->Arg(1)->Arg(2)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_LbmStepTubePlainWalls)->Arg(1)->Arg(2)->UseRealTime()->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
