// Topology and geometry of the paper's meshes: generate them, build the validated connectivity and
// compute every per-face and per-vertex quantity of MeshGeometry.
//   ./build/release/bench_geometry
#include <benchmark/benchmark.h>

#include "bendlab/geometry/mesh_geometry.hpp"
#include "bendlab/mesh/generators.hpp"

using namespace bendlab;

static void BM_TopologyBuild(benchmark::State& state) {
  const TriMesh mesh = sphere_mesh(MeshFamily::MT1, static_cast<int>(state.range(0)));
  for (auto _ : state) {
    auto t = Topology::build(mesh.num_vertices(), mesh.faces());
    benchmark::DoNotOptimize(t.get());
  }
  state.counters["triangles"] = mesh.num_faces();
  state.counters["vertices_per_s"] = benchmark::Counter(mesh.num_vertices(), benchmark::Counter::kIsIterationInvariantRate);
}
BENCHMARK(BM_TopologyBuild)->Arg(3)->Arg(6)->Unit(benchmark::kMillisecond);

// The whole MT1 generator (icosahedron, Loop-rule refinement, projection, validated TriMesh).
static void BM_SphereMeshBuild(benchmark::State& state) {
  int faces = 0;
  for (auto _ : state) {
    const TriMesh m = sphere_mesh(MeshFamily::MT1, static_cast<int>(state.range(0)));
    faces = m.num_faces();
    benchmark::DoNotOptimize(m.positions().data());
  }
  state.counters["triangles"] = faces;
}
BENCHMARK(BM_SphereMeshBuild)->Arg(6)->Unit(benchmark::kMillisecond);

static void BM_MeshGeometry(benchmark::State& state) {
  const TriMesh mesh = sphere_mesh(MeshFamily::MT1, static_cast<int>(state.range(0)));
  for (auto _ : state) {
    auto g = MeshGeometry::compute(mesh.topology(), mesh.positions());
    benchmark::DoNotOptimize(g.mixed_area.data());
  }
  state.counters["triangles"] = mesh.num_faces();
  state.counters["vertices_per_s"] = benchmark::Counter(mesh.num_vertices(), benchmark::Counter::kIsIterationInvariantRate);
}
BENCHMARK(BM_MeshGeometry)->Arg(3)->Arg(6)->Unit(benchmark::kMillisecond);

static void BM_TopologyPlusGeometry(benchmark::State& state) {
  const TriMesh mesh = sphere_mesh(MeshFamily::MT1, static_cast<int>(state.range(0)));
  for (auto _ : state) {
    TriMesh m(mesh.positions(), mesh.faces());
    auto g = MeshGeometry::compute(m.topology(), m.positions());
    benchmark::DoNotOptimize(g.mixed_area.data());
  }
  state.counters["triangles"] = mesh.num_faces();
}
BENCHMARK(BM_TopologyPlusGeometry)->Arg(6)->Unit(benchmark::kMillisecond);

BENCHMARK_MAIN();
