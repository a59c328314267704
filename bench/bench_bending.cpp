// Bending force evaluation of every method on the red blood cell of the paper's section 3
// (MT1 sphere meshes mapped onto the RBC), with 1 and 2 OpenMP threads.
//   ./build/release/bench_bending
//   ./build/release/bench_bending --benchmark_filter='BM_Compute/C/'
//
// Benchmarks (arguments: triangles, OpenMP threads):
//   BM_Compute/<method>    BendingMethod::compute_into (every per-vertex quantity, into a result kept
//                          from iteration to iteration, as a time loop keeps it), every registered
//                          method (`bendlab methods`: A..E, ED, S, J, M)
//   BM_Forces/<method>     BendingMethod::forces (node forces only: what a flow run calls) of every
//                          method but the O(N^2) ones, at 5120, 20480 and 81920 triangles, alternating
//                          between two nearby shapes. The ratio BM_Forces/S / BM_Forces/C is Method
//                          S's cost relative to Method C (docs/design.md).
//   BM_Compute/E_rings<R>  Method E with neighbourhoods of R = 2 and 3 rings, 5120 triangles (every
//                          O(N) method with a "rings" option)
//   BM_Order/<Q>/after:<P> Method Q's compute_into at 81920 triangles, one thread, right after an
//                          instance of method P ran (3 calls) and was destroyed, as when the
//                          benchmarks of P and Q follow each other: every method after every
//                          other. Q's time should not depend on P (docs/benchmarks.md, "Order of the
//                          methods"; the cause it guards against: bending/method_workspace.hpp).
//                          On a shared machine run it with --benchmark_repetitions=3
//                          --benchmark_enable_random_interleaving=true, so that a drift of the load
//                          is not taken for an effect of the order.
//   BM_ForcesRatio/M/over:C Method M's forces and Method C's in every iteration of one run (20480
//                          triangles, one thread, the two shapes of BM_Forces): counter ratio =
//                          (M's thread CPU time) / (C's), summed over the iterations, so that a drift
//                          of the machine's speed during the run (another process on the sibling
//                          core, the clock) falls on both alike; m_ms and c_ms are the per-call times.
//   BM_MongeJetFit/<path>  Method M's fits alone (steps 3-5, METHOD_M.md) at every node of the RBC at
//                          20480 triangles, one thread, on the 3-ring supports and covariance frames
//                          the method uses: path lanes (monge_jet_fit_nodes, 8 nodes side by side in
//                          SIMD lanes, the method's) or reference (monge_jet_fit_point, one node at a
//                          time, Eigen's fixed-size Cholesky), at degrees 5 and 6.
// Counters: vertices_per_s (vertices / wall-clock second) and vertices_per_s_per_thread (the same
// divided by the OpenMP threads); page_faults_per_call (minor page faults of the process per timed
// call, getrusage: memory the call touches for the first time since the kernel handed it out,
// which a method that allocates nothing once warm does not cause). Times are wall-clock
// (UseRealTime), since the work runs on OpenMP threads. Every benchmark makes two untimed calls
// first (what a method sets up once per mesh, and its workspace).
//
// A method whose registry cost class is O(N^2) runs a single iteration at 81920 triangles and has
// no BM_Forces row. Methods D and ED are O(N) (Belkin's heat kernel truncated at kernel_cutoff,
// through a cell list, belkin.hpp); their O(N^2) reference form is timed by bench/belkin_neighbours.
#include <benchmark/benchmark.h>
#include <omp.h>
#include <sys/resource.h>

#include <cmath>
#include <ctime>
#include <map>
#include <memory>
#include <string>

#include "bendlab/bending/method_registry.hpp"
#include "bendlab/bending/monge_jet.hpp"
#include "bendlab/geometry/mesh_geometry.hpp"
#include "bendlab/mesh/neighbourhood.hpp"
#include "bendlab/mesh/generators.hpp"
#include "bendlab/surfaces/analytic_surface.hpp"

using namespace bendlab;

namespace {

// The RBC mesh of a size, built once per program (generation is not what is measured).
const TriMesh& rbc_mesh(int triangles) {
  static std::map<int, std::unique_ptr<TriMesh>> cache;
  auto& m = cache[triangles];
  if (!m) {
    const TriMesh sphere = sphere_mesh(MeshFamily::MT1, level_with_triangles(MeshFamily::MT1, triangles));
    m = std::make_unique<TriMesh>(sphere.with_positions(make_rbc()->map_from_unit_sphere(sphere.positions())));
  }
  return *m;
}

void set_counters(benchmark::State& state, const TriMesh& mesh, int threads) {
  state.counters["triangles"] = mesh.num_faces();
  state.counters["vertices"] = mesh.num_vertices();
  state.counters["threads"] = threads;
  state.counters["vertices_per_s"] =
      benchmark::Counter(mesh.num_vertices(), benchmark::Counter::kIsIterationInvariantRate);
  state.counters["vertices_per_s_per_thread"] =
      benchmark::Counter(static_cast<double>(mesh.num_vertices()) / threads,
                         benchmark::Counter::kIsIterationInvariantRate);
}

// Minor page faults of the process so far.
long minor_faults() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return u.ru_minflt;
}

void set_fault_counter(benchmark::State& state, long faults) {
  state.counters["page_faults_per_call"] =
      benchmark::Counter(static_cast<double>(faults), benchmark::Counter::kAvgIterations);
}

void BM_Compute(benchmark::State& state, const std::string& method, const MethodOptions& options) {
  const TriMesh& mesh = rbc_mesh(static_cast<int>(state.range(0)));
  const int threads = static_cast<int>(state.range(1));
  omp_set_num_threads(threads);
  const auto m = make_bending_method(method, options);
  BendingResult r;
  // Untimed: the workspace; the second call lets the arrays the result and the workspace trade
  // (method_workspace.hpp) settle.
  for (int k = 0; k < 2; ++k) m->compute_into(mesh.topology(), mesh.positions(), 1.0, r);
  const long faults = minor_faults();
  for (auto _ : state) {
    m->compute_into(mesh.topology(), mesh.positions(), 1.0, r);
    benchmark::DoNotOptimize(r.force.data());
    benchmark::ClobberMemory();
  }
  set_fault_counter(state, minor_faults() - faults);
  set_counters(state, mesh, threads);
}

// Method `method` right after an instance of `before` ran and was destroyed (BM_Order above).
void BM_Order(benchmark::State& state, const std::string& method, const std::string& before) {
  const TriMesh& mesh = rbc_mesh(81920);
  omp_set_num_threads(1);
  {
    const auto p = make_bending_method(before);
    BendingResult r;
    for (int k = 0; k < 3; ++k) p->compute_into(mesh.topology(), mesh.positions(), 1.0, r);
  }
  const auto m = make_bending_method(method);
  BendingResult r;
  // Untimed: the workspace; the second call lets the arrays the result and the workspace trade
  // (method_workspace.hpp) settle.
  for (int k = 0; k < 2; ++k) m->compute_into(mesh.topology(), mesh.positions(), 1.0, r);
  const long faults = minor_faults();
  for (auto _ : state) {
    m->compute_into(mesh.topology(), mesh.positions(), 1.0, r);
    benchmark::DoNotOptimize(r.force.data());
    benchmark::ClobberMemory();
  }
  set_fault_counter(state, minor_faults() - faults);
  set_counters(state, mesh, 1);
}

void BM_Forces(benchmark::State& state, const std::string& method) {
  const TriMesh& mesh = rbc_mesh(static_cast<int>(state.range(0)));
  const int threads = static_cast<int>(state.range(1));
  omp_set_num_threads(threads);
  const auto m = make_bending_method(method);
  Points force(mesh.num_vertices(), 3);
  // Two shapes in turn, as successive stages of a flow run see (a smooth relative change of 1e-3):
  // a method that reuses its previous solution (S's warm-started mass solve) is not timed on a
  // shape it has just solved.
  Points moved = mesh.positions();
  for (Eigen::Index i = 0; i < moved.rows(); ++i) moved.row(i) *= 1.0 + 1e-3 * std::sin(3.0 * moved(i, 0));
  const Points* shapes[2] = {&mesh.positions(), &moved};
  int k = 0;
  // Untimed: what a method sets up once per topology (S: patches, factorisation of L, mass pattern), as a
  // flow run pays it once.
  m->forces(mesh.topology(), moved, 1.0, force);
  m->forces(mesh.topology(), mesh.positions(), 1.0, force);
  const long faults = minor_faults();
  for (auto _ : state) {
    m->forces(mesh.topology(), *shapes[k ^= 1], 1.0, force);
    benchmark::DoNotOptimize(force.data());
    benchmark::ClobberMemory();
  }
  set_fault_counter(state, minor_faults() - faults);
  set_counters(state, mesh, threads);
}

// The thread's CPU time in seconds.
double thread_cpu_seconds() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

// `method` and `reference` in turn on the shapes of BM_Forces (BM_ForcesRatio above).
void BM_ForcesRatio(benchmark::State& state, const std::string& method, const std::string& reference) {
  const TriMesh& mesh = rbc_mesh(static_cast<int>(state.range(0)));
  omp_set_num_threads(1);
  const auto m = make_bending_method(method), r = make_bending_method(reference);
  Points force(mesh.num_vertices(), 3);
  Points moved = mesh.positions();
  for (Eigen::Index i = 0; i < moved.rows(); ++i) moved.row(i) *= 1.0 + 1e-3 * std::sin(3.0 * moved(i, 0));
  const Points* shapes[2] = {&mesh.positions(), &moved};
  for (const Points* x : shapes) {  // untimed: each method's set-up and workspace
    m->forces(mesh.topology(), *x, 1.0, force);
    r->forces(mesh.topology(), *x, 1.0, force);
  }
  double t_method = 0, t_reference = 0;
  int k = 0;
  for (auto _ : state) {
    const Points& x = *shapes[k ^= 1];
    const double t0 = thread_cpu_seconds();
    r->forces(mesh.topology(), x, 1.0, force);
    const double t1 = thread_cpu_seconds();
    m->forces(mesh.topology(), x, 1.0, force);
    const double t2 = thread_cpu_seconds();
    benchmark::DoNotOptimize(force.data());
    benchmark::ClobberMemory();
    t_reference += t1 - t0;
    t_method += t2 - t1;
  }
  const double calls = static_cast<double>(state.iterations());
  state.counters["ratio"] = t_reference > 0 ? t_method / t_reference : 0.0;
  state.counters["m_ms"] = 1e3 * t_method / calls;
  state.counters["c_ms"] = 1e3 * t_reference / calls;
  state.counters["triangles"] = mesh.num_faces();
}

// Method M's fits alone, by the batched path (lanes = true) or the per-node reference.
void BM_MongeJetFit(benchmark::State& state, bool lanes) {
  const int degree = static_cast<int>(state.range(0));
  const TriMesh& mesh = rbc_mesh(20480);
  const Points& x = mesh.positions();
  const MeshGeometry geometry = MeshGeometry::compute(mesh.topology(), x);
  const int n = mesh.num_vertices();
  std::vector<std::vector<Vec3>> supports(n);
  std::vector<MongeJetNode> nodes(n);
  VertexRings rings(mesh.topology());
  for (int i = 0; i < n; ++i) {
    rings.start(i);
    rings.grow_to(3);
    for (const int v : rings.vertices()) supports[i].push_back(x.row(v).transpose());
    const Vec3 x0 = x.row(i).transpose();
    nodes[i] = MongeJetNode{x0, covariance_normal(x0, supports[i], geometry.normal_mwa.row(i).transpose()), supports[i]};
  }
  for (auto _ : state) {
    if (lanes) {
      benchmark::DoNotOptimize(monge_jet_fit_nodes(nodes, degree));
    } else {
      double sum = 0;
      for (const MongeJetNode& node : nodes) sum += monge_jet_fit_point(node.x0, node.n0, node.support, degree).H;
      benchmark::DoNotOptimize(sum);
    }
  }
  state.counters["nodes_per_s"] = benchmark::Counter(n, benchmark::Counter::kIsIterationInvariantRate);
}

// Every registered method (bending/method_registry.hpp); its cost class decides the iterations.
void register_all() {
  for (const MethodInfo& info : bending_methods()) {
    const std::string method = info.name;
    const bool quadratic = info.capabilities.cost == "O(N^2)";
    for (const int triangles : {5120, 81920}) {
      for (const int threads : {1, 2}) {
        auto* b = benchmark::RegisterBenchmark(("BM_Compute/" + method).c_str(), BM_Compute, method, MethodOptions{});
        b->Args({triangles, threads})->ArgNames({"triangles", "threads"})->UseRealTime()->Unit(benchmark::kMillisecond);
        if (quadratic && triangles > 5120) b->Iterations(1);
      }
    }
  }
  for (const MethodInfo& info : bending_methods()) {
    if (info.capabilities.cost == "O(N^2)") continue;
    const std::string method = info.name;
    auto* b = benchmark::RegisterBenchmark(("BM_Forces/" + method).c_str(), BM_Forces, method);
    b->ArgsProduct({{5120, 20480, 81920}, {1, 2}})->ArgNames({"triangles", "threads"})->UseRealTime()
        ->Unit(benchmark::kMillisecond);
  }
  {
    auto* b = benchmark::RegisterBenchmark("BM_ForcesRatio/M/over:C", BM_ForcesRatio, std::string("M"),
                                           std::string("C"));
    b->Args({20480})->ArgNames({"triangles"})->UseRealTime()->Unit(benchmark::kMillisecond);
  }
  // Every method after every other, 81920 triangles, one thread. A fixed count of calls keeps the
  // 81 pairs to about a minute on the reference machine.
  for (const std::string& q : bending_method_names()) {
    for (const std::string& p : bending_method_names()) {
      auto* b = benchmark::RegisterBenchmark(("BM_Order/" + q + "/after:" + p).c_str(), BM_Order, q, p);
      b->Iterations(5)->UseRealTime()->Unit(benchmark::kMillisecond);
    }
  }
  for (const bool lanes : {true, false}) {
    auto* b = benchmark::RegisterBenchmark(lanes ? "BM_MongeJetFit/lanes" : "BM_MongeJetFit/reference",
                                           BM_MongeJetFit, lanes);
    b->ArgsProduct({{5, 6}})->ArgNames({"degree"})->Unit(benchmark::kMillisecond);
  }
  // Wider neighbourhoods of the linear-cost methods with a "rings" option (E).
  for (const MethodInfo& info : bending_methods()) {
    if (info.capabilities.cost != "O(N)") continue;
    for (const OptionSpec& o : info.options) {
      if (o.name != "rings") continue;
      for (int rings = static_cast<int>(o.min) + 1; rings <= static_cast<int>(o.max); ++rings) {
        const std::string name = "BM_Compute/" + info.name + "_rings" + std::to_string(rings);
        auto* b = benchmark::RegisterBenchmark(name.c_str(), BM_Compute, info.name,
                                               MethodOptions{{"rings", std::to_string(rings)}});
        b->ArgsProduct({{5120}, {1, 2}})->ArgNames({"triangles", "threads"})->UseRealTime()
            ->Unit(benchmark::kMillisecond);
      }
    }
  }
}

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  register_all();
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
