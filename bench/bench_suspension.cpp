// Many cells in a tube: the case of HemoCell's pipeflow example (CELLS_IN_CHANNELS.md; issue
// "Many cells in channel and tube flow"), one step of LbmSuspension and its parts.
//   ./build/release/bench_suspension
//
// Tube 25 um across and 50 um long at dx = 0.5 um (D = 50 dx, 100 x 54 x 54 nodes, TRT, body force
// for a pseudo-shear rate of 100 1/s at tau = 1), 36 red blood cells of 1280 triangles (Method C,
// Skalak, the physical defaults of flow/cell_kind.hpp) and 6 small stiff spheres (radius 1.5 um, 320
// triangles, ten times the shear modulus), placed from seed 1 with a clearance of 0.25 um; every
// force is updated every step (HemoCell updates membrane forces every 20 steps and positions every
// 5). Benchmarks (argument: OpenMP threads):
//   BM_PipeflowStep      one whole step: steps_per_second is the figure to set against HemoCell's
//                        26 (1 rank) and 48 (2 ranks) steps/s on this kind of machine;
//   BM_PipeflowStepEvery20  the same with membrane forces every 20 steps (flow --membrane-every
//                        20), HemoCell's default stepMaterialEvery: its figure to set against
//                        HemoCell's default updates (scripts/hemocell_like_for_like.py);
//   BM_PipeflowFluid     the fluid step alone (the same lattice, no cells): cells_fraction of the
//                        whole step = 1 - fluid / step, computed by scripts from the two.
//   BM_Tube10Step        the tube study's reference case at time scale 10 (D = 10 um, 5 red blood
//                        cells, tau 1.82; pipeflow_case.hpp), and BM_Tube10Fluid its fluid alone;
//   BM_PipeflowHt03Step  the same tube at tube hematocrit 0.3 (red blood cells only, placed by
//                        place_cells from seed 1 with the same clearance: 79 cells, grown from 0.6
//                        of their size where random addition jams at 47).
//   BM_ExtraCellMemory   the heap a suspension grows by per red blood cell added to the
//                        pipeflow case (20 more, stepped twice so that every per-vertex array has
//                        grown): bytes_per_cell and bytes_per_vertex, against positions and forces
//                        alone (48 bytes per vertex). Timed is nothing; its counters are the figure.
#include <malloc.h>
#include <benchmark/benchmark.h>
#include <omp.h>

#include <memory>

#include "bendlab/flow/cell_kind.hpp"
#include "bendlab/flow/lbm/lbm_suspension.hpp"
#include "bendlab/flow/lbm/physical_units.hpp"
#include "bendlab/suspension/placement.hpp"
#include "pipeflow_case.hpp"

using namespace bendlab;
using namespace bendlab::lbm;

namespace {

// The heap the process has in use, bytes (glibc's mallinfo2: allocated blocks, mapped ones
// included; blocks freed but kept by the allocator are not counted, as the resident set would).
double heap_in_use() {
  const struct mallinfo2 m = mallinfo2();
  return static_cast<double>(m.uordblks) + static_cast<double>(m.hblkhd);
}

std::unique_ptr<LbmSuspension> pipeflow(bool with_cells, double hematocrit = 0, int membrane_every = 1) {
  SuspensionOptions o = bench::pipeflow_options();
  o.membrane_every = membrane_every;
  auto s = std::make_unique<LbmSuspension>(o);
  if (with_cells) bench::add_pipeflow_cells(*s, hematocrit, [&] { return s->positions(); });
  return s;
}

void BM_PipeflowStep(benchmark::State& state) {
  omp_set_num_threads(static_cast<int>(state.range(0)));
  static std::unique_ptr<LbmSuspension> s = pipeflow(true);
  s->run(2);
  for (auto _ : state) s->step();
  state.counters["steps_per_second"] = benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
  state.counters["cells"] = s->num_cells();
  state.counters["vertices"] = static_cast<double>(s->positions().rows());
}

// HemoCell's default time-scale separation for the membrane: forces every 20 steps (flow
// --membrane-every 20), everything else every step.
void BM_PipeflowStepEvery20(benchmark::State& state) {
  omp_set_num_threads(static_cast<int>(state.range(0)));
  static std::unique_ptr<LbmSuspension> s = pipeflow(true, 0, 20);
  s->run(20);
  for (auto _ : state) s->step();
  state.counters["steps_per_second"] = benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
  state.counters["cells"] = s->num_cells();
  state.counters["vertices"] = static_cast<double>(s->positions().rows());
}

void BM_PipeflowFluid(benchmark::State& state) {
  omp_set_num_threads(static_cast<int>(state.range(0)));
  static std::unique_ptr<LbmSuspension> s = pipeflow(false);
  s->run(2);
  for (auto _ : state) s->step();
  state.counters["steps_per_second"] = benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
  state.counters["MLUPS"] = benchmark::Counter(static_cast<double>(state.iterations()) * s->lattice().num_fluid_nodes() * 1e-6,
                                               benchmark::Counter::kIsRate);
}

// The tube study's reference case at time scale 10 (pipeflow_case.hpp: tube10_options), the
// fluid alone and the whole step.
void BM_Tube10Step(benchmark::State& state) {
  omp_set_num_threads(static_cast<int>(state.range(0)));
  static std::unique_ptr<LbmSuspension> s;
  if (!s) {
    s = std::make_unique<LbmSuspension>(bench::tube10_options());
    bench::add_tube10_cells(*s);
  }
  s->run(2);
  for (auto _ : state) s->step();
  state.counters["steps_per_second"] = benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
  state.counters["cells"] = s->num_cells();
  state.counters["vertices"] = static_cast<double>(s->positions().rows());
}

void BM_Tube10Fluid(benchmark::State& state) {
  omp_set_num_threads(static_cast<int>(state.range(0)));
  static std::unique_ptr<LbmSuspension> s = std::make_unique<LbmSuspension>(bench::tube10_options());
  s->run(2);
  for (auto _ : state) s->step();
  state.counters["steps_per_second"] = benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}

void BM_PipeflowHt03Step(benchmark::State& state) {
  omp_set_num_threads(static_cast<int>(state.range(0)));
  static std::unique_ptr<LbmSuspension> s;
  static std::string placement_error;
  if (!s && placement_error.empty()) {
    try {
      s = pipeflow(true, 0.3);
    } catch (const Error& e) {
      placement_error = e.what();
    }
  }
  if (!s) {
    state.SkipWithError(placement_error.c_str());
    for (auto _ : state) {
    }
    return;
  }
  s->run(2);
  for (auto _ : state) s->step();
  state.counters["steps_per_second"] = benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
  state.counters["cells"] = s->num_cells();
  state.counters["vertices"] = static_cast<double>(s->positions().rows());
}

void BM_ExtraCellMemory(benchmark::State& state) {
  omp_set_num_threads(1);
  std::unique_ptr<LbmSuspension> s = pipeflow(true);
  s->run(2);
  const double before = heap_in_use();
  const int first_red = 0, extra = 20;
  const Points red = s->cell_positions(first_red);
  // Copies of the first cell shifted along the axis by a period: where it is, so that the run
  // stays finite (their contact forces are capped); the memory is what is measured.
  const std::shared_ptr<const MembraneModel> membrane(std::shared_ptr<const MembraneModel>(), &s->membrane(first_red));
  for (int k = 0; k < extra; ++k) {
    Points x = red;
    x.col(0).array() += s->lattice().nx() * (k + 1);
    s->add_cell(membrane, x);
  }
  s->run(2);
  const double after = heap_in_use();
  for (auto _ : state) benchmark::DoNotOptimize(after);
  state.counters["bytes_per_cell"] = (after - before) / extra;
  state.counters["bytes_per_vertex"] = (after - before) / (extra * static_cast<double>(red.rows()));
}

}  // namespace

BENCHMARK(BM_PipeflowFluid)->Arg(1)->Arg(2)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_PipeflowStep)->Arg(1)->Arg(2)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_PipeflowStepEvery20)->Arg(1)->Arg(2)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Tube10Fluid)->Arg(1)->Arg(2)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Tube10Step)->Arg(1)->Arg(2)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_PipeflowHt03Step)->Arg(1)->Arg(2)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ExtraCellMemory)->Iterations(1)->Unit(benchmark::kMillisecond);
BENCHMARK_MAIN();
