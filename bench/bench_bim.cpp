// One evaluation of the Stokes single layer (the boundary integral of the shear-flow solver) on
// MT1 spheres, against reference kernels measuring what the machine does with the same shape.
//   ./build/release/bench_bim
//
// Benchmarks (arguments: triangles, OpenMP threads):
//   BM_SingleLayer/<quadrature>
//                         StokesSingleLayer::velocity at every node, force density f = n z
//                         (n the outward normal): quadrature set-up, the regular rule (all7: the
//                         7-point rule over every triangle for every node; adaptive: the 7-point
//                         rule near, the moment-corrected centroid rule far; tree: the 7-point
//                         rule near, cluster-tree proxies far), and the polar integrals at each
//                         node's triangles.
//   BM_QuadratureRatio/<shape>[_tree] (arguments: triangles, threads) all7 and adaptive (or tree)
//                         on one shape in every iteration, force density = Method C's bending
//                         force density (kB = 1) on that shape: counters speedup = (time of all7) /
//                         (time of the other rule), summed over the iterations of this one run,
//                         and rel_diff = max_i |u(x_i) - u_all7(x_i)| / max_i |u_all7(x_i)|. Shapes: the
//                         red blood cell of eq. (15) (R = 1) and the ellipsoid of half axes
//                         2, 1, 0.5, both mapped from the MT1 sphere.
//   BM_TreeParameters/<shape>/leaf:L/degree:Q/tolerance_1e-7:T
//                         as BM_QuadratureRatio at 5120 triangles on one thread, the tree with
//                         leaves of at most L triangles, degree Q and tolerance T x 1e-7 (a scan
//                         around the defaults 32, 7, 2e-6).
//   BM_StokesletReference/<isa>
//                         the regular part alone, on contiguous arrays: for every node, the
//                         Stokeslet sum over the 7 N_T quadrature points of the same mesh, with the
//                         same arithmetic and nothing else (no set-up, no singular triangles), in
//                         three forms: `baseline` (the build's default instruction set, blocked
//                         as the default errno semantics of sqrt require), `avx2` (4-wide with
//                         FMA) and `avx512` (8-wide), the last two written with intrinsics and
//                         skipped where the processor lacks them. The fastest is what this machine
//                         does with the kernel's shape; BM_SingleLayer pairs_per_s over it is the
//                         efficiency of the solver's kernel.
//   BM_MultiplyAddPeak/<isa> (argument: threads) independent multiply-add chains in registers: the
//                         arithmetic peak of each instruction set on this machine, flops per second.
// Counters: pairs_per_s = N_vertices * N_triangles * 7 (target-source pairs) per wall-clock
// second, pairs_per_s_per_thread, and s_per_eval (seconds per evaluation, = the time column).
#include <benchmark/benchmark.h>
#include <omp.h>

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <map>
#include <memory>
#include <vector>
#if defined(__x86_64__) && defined(__GNUC__)
#include <immintrin.h>
#endif

#include "bendlab/bending/bending_method.hpp"
#include "bendlab/flow/bim/stokes_single_layer.hpp"
#include "bendlab/mesh/generators.hpp"
#include "bendlab/surfaces/analytic_surface.hpp"

using namespace bendlab;

namespace {

const TriMesh& unit_sphere(int triangles) {
  static std::map<int, std::unique_ptr<TriMesh>> cache;
  auto& m = cache[triangles];
  if (!m) m = std::make_unique<TriMesh>(sphere_mesh(MeshFamily::MT1, level_with_triangles(MeshFamily::MT1, triangles)));
  return *m;
}

// A smooth force density on the unit sphere: f = n z, n = x / |x|.
Points smooth_density(const Points& x) {
  Points f(x.rows(), 3);
  for (Eigen::Index i = 0; i < x.rows(); ++i) {
    const Vec3 n = row(x, i).normalized();
    f.row(i) = (n * x(i, 2)).transpose();
  }
  return f;
}

void set_pair_counters(benchmark::State& state, const TriMesh& mesh, int threads) {
  const double pairs = 7.0 * mesh.num_vertices() * mesh.num_faces();
  state.counters["triangles"] = mesh.num_faces();
  state.counters["vertices"] = mesh.num_vertices();
  state.counters["threads"] = threads;
  state.counters["pairs_per_s"] = benchmark::Counter(pairs, benchmark::Counter::kIsIterationInvariantRate);
  state.counters["pairs_per_s_per_thread"] =
      benchmark::Counter(pairs / threads, benchmark::Counter::kIsIterationInvariantRate);
  // Rate of 1 per iteration, inverted: seconds per evaluation.
  state.counters["s_per_eval"] =
      benchmark::Counter(1.0, benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}

void BM_SingleLayer(benchmark::State& state, SingleLayerQuadrature quadrature) {
  const TriMesh& mesh = unit_sphere(static_cast<int>(state.range(0)));
  const int threads = static_cast<int>(state.range(1));
  omp_set_num_threads(threads);
  SingleLayerOptions options;
  options.quadrature = quadrature;
  const StokesSingleLayer single_layer(mesh.topology_ptr(), options);
  const Points f = smooth_density(mesh.positions());
  Points u(mesh.num_vertices(), 3);
  for (auto _ : state) {
    single_layer.velocity(mesh.positions(), f, 1.0, u);
    benchmark::DoNotOptimize(u.data());
    benchmark::ClobberMemory();
  }
  set_pair_counters(state, mesh, threads);
}
#define BENDLAB_SINGLE_LAYER(name, q)                \
  BENCHMARK_CAPTURE(BM_SingleLayer, name, q)          \
      ->ArgsProduct({{1280, 5120, 20480}, {1, 2}})    \
      ->ArgNames({"triangles", "threads"})            \
      ->UseRealTime()                                 \
      ->Unit(benchmark::kMillisecond)
BENDLAB_SINGLE_LAYER(all7, SingleLayerQuadrature::all7);
BENDLAB_SINGLE_LAYER(adaptive, SingleLayerQuadrature::adaptive);
BENDLAB_SINGLE_LAYER(tree, SingleLayerQuadrature::tree);
BENDLAB_SINGLE_LAYER(tree_mixed, SingleLayerQuadrature::tree_mixed);

enum Shape { kRbc, kEllipsoid };

// all7 (the reference) and `options` on one shape in every iteration; the counters of
// BM_QuadratureRatio.
void quadrature_ratio(benchmark::State& state, Shape shape, int triangles, int threads, const SingleLayerOptions& other_options) {
  const TriMesh& sphere = unit_sphere(triangles);
  omp_set_num_threads(threads);
  Points x = sphere.positions();
  if (shape == kRbc) {
    x = make_rbc(1.0)->map_from_unit_sphere(x);
  } else {
    x.col(0) *= 2.0;
    x.col(2) *= 0.5;
  }
  const BendingResult bending = make_bending_method("C")->compute(sphere.topology(), x, 1.0);
  const Points& f = bending.force_density;
  SingleLayerOptions reference_options;
  reference_options.quadrature = SingleLayerQuadrature::all7;
  const StokesSingleLayer reference(sphere.topology_ptr(), reference_options);
  const StokesSingleLayer other(sphere.topology_ptr(), other_options);
  Points u_ref(x.rows(), 3), u(x.rows(), 3);
  double t_ref = 0, t_other = 0;
  using Clock = std::chrono::steady_clock;
  for (auto _ : state) {
    const auto t0 = Clock::now();
    reference.velocity(x, f, 1.0, u_ref);
    const auto t1 = Clock::now();
    other.velocity(x, f, 1.0, u);
    const auto t2 = Clock::now();
    benchmark::DoNotOptimize(u.data());
    benchmark::DoNotOptimize(u_ref.data());
    t_ref += std::chrono::duration<double>(t1 - t0).count();
    t_other += std::chrono::duration<double>(t2 - t1).count();
  }
  state.counters["triangles"] = sphere.num_faces();
  state.counters["threads"] = threads;
  state.counters["s_all7"] = t_ref / static_cast<double>(state.iterations());
  state.counters["s_" + to_string(other_options.quadrature)] = t_other / static_cast<double>(state.iterations());
  state.counters["speedup"] = t_ref / t_other;
  state.counters["rel_diff"] = (u - u_ref).rowwise().norm().maxCoeff() / u_ref.rowwise().norm().maxCoeff();
}

void BM_QuadratureRatio(benchmark::State& state, Shape shape, SingleLayerQuadrature quadrature) {
  SingleLayerOptions options;
  options.quadrature = quadrature;
  quadrature_ratio(state, shape, static_cast<int>(state.range(0)), static_cast<int>(state.range(1)), options);
}

// The tree around its defaults at 5120 triangles, one thread: arguments leaf size, degree and
// tolerance in units of 1e-7 (the scan behind the parameters in stokes_single_layer.hpp).
void BM_TreeParameters(benchmark::State& state, Shape shape) {
  SingleLayerOptions options;
  options.quadrature = SingleLayerQuadrature::tree;
  options.tree_leaf_size = static_cast<int>(state.range(0));
  options.tree_order = static_cast<int>(state.range(1));
  options.tree_tolerance = 1e-7 * static_cast<double>(state.range(2));
  quadrature_ratio(state, shape, 5120, 1, options);
}
#define BENDLAB_RATIO(name, shape, q)                    \
  BENCHMARK_CAPTURE(BM_QuadratureRatio, name, shape, q)  \
      ->ArgsProduct({{1280, 5120, 20480}, {1, 2}})    \
      ->ArgNames({"triangles", "threads"})            \
      ->UseRealTime()                                 \
      ->Unit(benchmark::kMillisecond)
BENDLAB_RATIO(rbc, kRbc, SingleLayerQuadrature::adaptive);
BENDLAB_RATIO(ellipsoid, kEllipsoid, SingleLayerQuadrature::adaptive);
BENDLAB_RATIO(rbc_tree, kRbc, SingleLayerQuadrature::tree);
BENDLAB_RATIO(ellipsoid_tree, kEllipsoid, SingleLayerQuadrature::tree);
BENDLAB_RATIO(rbc_tree_mixed, kRbc, SingleLayerQuadrature::tree_mixed);
BENDLAB_RATIO(ellipsoid_tree_mixed, kEllipsoid, SingleLayerQuadrature::tree_mixed);

#define BENDLAB_TREE_SCAN(name, shape)                                                  \
  BENCHMARK_CAPTURE(BM_TreeParameters, name, shape)                                      \
      ->Args({32, 7, 20})->Args({16, 7, 20})->Args({48, 7, 20})->Args({64, 7, 20})        \
      ->Args({32, 6, 20})->Args({32, 8, 20})->Args({32, 7, 40})                            \
      ->ArgNames({"leaf", "degree", "tolerance_1e-7"})                                     \
      ->UseRealTime()                                                                      \
      ->Unit(benchmark::kMillisecond)
BENDLAB_TREE_SCAN(rbc, kRbc);
BENDLAB_TREE_SCAN(ellipsoid, kEllipsoid);

// Quadrature points and weighted densities of the 7-point rule on every triangle, structure of
// arrays, as the solver lays them out.
struct SourceArrays {
  std::vector<double> qx, qy, qz, fx, fy, fz;
};

SourceArrays source_arrays(const TriMesh& mesh, const Points& f) {
  const Faces& F = mesh.faces();
  const Points& x = mesh.positions();
  const TriangleRule7& rule = triangle_rule7();
  const std::size_t nq = 7 * static_cast<std::size_t>(mesh.num_faces());
  SourceArrays s;
  for (auto* v : {&s.qx, &s.qy, &s.qz, &s.fx, &s.fy, &s.fz}) v->resize(nq);
  for (int t = 0; t < mesh.num_faces(); ++t) {
    const Vec3 x0 = row(x, F(t, 0)), x1 = row(x, F(t, 1)), x2 = row(x, F(t, 2));
    const Vec3 f0 = row(f, F(t, 0)), f1 = row(f, F(t, 1)), f2 = row(f, F(t, 2));
    const double area = 0.5 * (x1 - x0).cross(x2 - x0).norm();
    for (int q = 0; q < 7; ++q) {
      const double* l = rule.bary[q];
      const Vec3 y = l[0] * x0 + l[1] * x1 + l[2] * x2;
      const Vec3 fw = rule.weight[q] * area * (l[0] * f0 + l[1] * f1 + l[2] * f2);
      const std::size_t k = 7 * static_cast<std::size_t>(t) + q;
      s.qx[k] = y.x(); s.qy[k] = y.y(); s.qz[k] = y.z();
      s.fx[k] = fw.x(); s.fy[k] = fw.y(); s.fz[k] = fw.z();
    }
  }
  return s;
}

// Instruction sets of the reference kernels: the build's baseline, and where the compiler and the
// processor allow, AVX2 with FMA (4 doubles a vector) and AVX-512 (8 doubles).
enum Isa { kBaseline, kAvx2, kAvx512 };

#if defined(__x86_64__) && defined(__GNUC__)
#define BENDLAB_BENCH_X86 1
#endif

bool isa_supported(Isa isa) {
#ifdef BENDLAB_BENCH_X86
  if (isa == kAvx2) return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
  if (isa == kAvx512) return __builtin_cpu_supports("avx512f");
#endif
  return isa == kBaseline;
}

// The Stokeslet sum u = sum_k f_k / r + r (f_k . r) / r^3, r = y_k - x, for one target x over
// contiguous arrays. Baseline: the build's default flags keep errno semantics for std::sqrt,
// which stops a fused loop from vectorising, so 1/r goes through Eigen's packet sqrt one block at
// a time, then the block is accumulated.
void stokeslet_sum_baseline(double xi, double yi, double zi, const SourceArrays& s, double* out) {
  const int nq = static_cast<int>(s.qx.size());
  const double* qx = s.qx.data(); const double* qy = s.qy.data(); const double* qz = s.qz.data();
  const double* fx = s.fx.data(); const double* fy = s.fy.data(); const double* fz = s.fz.data();
  constexpr int B = 256;
  alignas(64) std::array<double, B> inv_r;
  double ux = 0, uy = 0, uz = 0;
  for (int q0 = 0; q0 < nq; q0 += B) {
    const int n = std::min(B, nq - q0);
#pragma omp simd
    for (int q = 0; q < n; ++q) {
      const double dx = qx[q0 + q] - xi, dy = qy[q0 + q] - yi, dz = qz[q0 + q] - zi;
      inv_r[q] = dx * dx + dy * dy + dz * dz;
    }
    Eigen::Map<Eigen::ArrayXd> ir(inv_r.data(), n);
    ir = ir.sqrt().inverse();
#pragma omp simd reduction(+ : ux, uy, uz)
    for (int q = 0; q < n; ++q) {
      const int k = q0 + q;
      const double dx = qx[k] - xi, dy = qy[k] - yi, dz = qz[k] - zi;
      const double r1 = inv_r[q];
      const double fr = (fx[k] * dx + fy[k] * dy + fz[k] * dz) * r1 * r1 * r1;
      ux += fx[k] * r1 + dx * fr;
      uy += fy[k] * r1 + dy * fr;
      uz += fz[k] * r1 + dz * fr;
    }
  }
  out[0] = ux;
  out[1] = uy;
  out[2] = uz;
}

// The scalar remainder of the vector kernels.
void stokeslet_tail(double xi, double yi, double zi, const SourceArrays& s, int k0, double* out) {
  for (std::size_t k = k0; k < s.qx.size(); ++k) {
    const double dx = s.qx[k] - xi, dy = s.qy[k] - yi, dz = s.qz[k] - zi;
    const double r1 = 1.0 / std::sqrt(dx * dx + dy * dy + dz * dz);
    const double fr = (s.fx[k] * dx + s.fy[k] * dy + s.fz[k] * dz) * r1 * r1 * r1;
    out[0] += s.fx[k] * r1 + dx * fr;
    out[1] += s.fy[k] * r1 + dy * fr;
    out[2] += s.fz[k] * r1 + dz * fr;
  }
}

#ifdef BENDLAB_BENCH_X86
__attribute__((target("avx2,fma"))) void stokeslet_sum_avx2(double xi, double yi, double zi, const SourceArrays& s,
                                                             double* out) {
  const int nq = static_cast<int>(s.qx.size());
  const __m256d X = _mm256_set1_pd(xi), Y = _mm256_set1_pd(yi), Z = _mm256_set1_pd(zi), one = _mm256_set1_pd(1.0);
  __m256d ux = _mm256_setzero_pd(), uy = _mm256_setzero_pd(), uz = _mm256_setzero_pd();
  int k = 0;
  for (; k + 4 <= nq; k += 4) {
    const __m256d dx = _mm256_sub_pd(_mm256_loadu_pd(&s.qx[k]), X);
    const __m256d dy = _mm256_sub_pd(_mm256_loadu_pd(&s.qy[k]), Y);
    const __m256d dz = _mm256_sub_pd(_mm256_loadu_pd(&s.qz[k]), Z);
    const __m256d fx = _mm256_loadu_pd(&s.fx[k]), fy = _mm256_loadu_pd(&s.fy[k]), fz = _mm256_loadu_pd(&s.fz[k]);
    const __m256d r2 = _mm256_fmadd_pd(dx, dx, _mm256_fmadd_pd(dy, dy, _mm256_mul_pd(dz, dz)));
    const __m256d r1 = _mm256_div_pd(one, _mm256_sqrt_pd(r2));
    const __m256d fdr = _mm256_fmadd_pd(fx, dx, _mm256_fmadd_pd(fy, dy, _mm256_mul_pd(fz, dz)));
    const __m256d fr = _mm256_mul_pd(fdr, _mm256_mul_pd(r1, _mm256_mul_pd(r1, r1)));
    ux = _mm256_fmadd_pd(dx, fr, _mm256_fmadd_pd(fx, r1, ux));
    uy = _mm256_fmadd_pd(dy, fr, _mm256_fmadd_pd(fy, r1, uy));
    uz = _mm256_fmadd_pd(dz, fr, _mm256_fmadd_pd(fz, r1, uz));
  }
  alignas(32) double a[4], b[4], c[4];
  _mm256_store_pd(a, ux);
  _mm256_store_pd(b, uy);
  _mm256_store_pd(c, uz);
  out[0] = a[0] + a[1] + a[2] + a[3];
  out[1] = b[0] + b[1] + b[2] + b[3];
  out[2] = c[0] + c[1] + c[2] + c[3];
  stokeslet_tail(xi, yi, zi, s, k, out);
}

// GCC 12's AVX-512 headers initialise an undefined vector from itself (_mm512_undefined_pd),
// which -Wuninitialized reports at every inlined reduction or sqrt; the warning is about the
// header, not this code.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wuninitialized"
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
__attribute__((target("avx512f"))) void stokeslet_sum_avx512(double xi, double yi, double zi, const SourceArrays& s,
                                                              double* out) {
  const int nq = static_cast<int>(s.qx.size());
  const __m512d X = _mm512_set1_pd(xi), Y = _mm512_set1_pd(yi), Z = _mm512_set1_pd(zi), one = _mm512_set1_pd(1.0);
  __m512d ux = _mm512_setzero_pd(), uy = _mm512_setzero_pd(), uz = _mm512_setzero_pd();
  int k = 0;
  for (; k + 8 <= nq; k += 8) {
    const __m512d dx = _mm512_sub_pd(_mm512_loadu_pd(&s.qx[k]), X);
    const __m512d dy = _mm512_sub_pd(_mm512_loadu_pd(&s.qy[k]), Y);
    const __m512d dz = _mm512_sub_pd(_mm512_loadu_pd(&s.qz[k]), Z);
    const __m512d fx = _mm512_loadu_pd(&s.fx[k]), fy = _mm512_loadu_pd(&s.fy[k]), fz = _mm512_loadu_pd(&s.fz[k]);
    const __m512d r2 = _mm512_fmadd_pd(dx, dx, _mm512_fmadd_pd(dy, dy, _mm512_mul_pd(dz, dz)));
    const __m512d r1 = _mm512_div_pd(one, _mm512_sqrt_pd(r2));
    const __m512d fdr = _mm512_fmadd_pd(fx, dx, _mm512_fmadd_pd(fy, dy, _mm512_mul_pd(fz, dz)));
    const __m512d fr = _mm512_mul_pd(fdr, _mm512_mul_pd(r1, _mm512_mul_pd(r1, r1)));
    ux = _mm512_fmadd_pd(dx, fr, _mm512_fmadd_pd(fx, r1, ux));
    uy = _mm512_fmadd_pd(dy, fr, _mm512_fmadd_pd(fy, r1, uy));
    uz = _mm512_fmadd_pd(dz, fr, _mm512_fmadd_pd(fz, r1, uz));
  }
  out[0] = _mm512_reduce_add_pd(ux);
  out[1] = _mm512_reduce_add_pd(uy);
  out[2] = _mm512_reduce_add_pd(uz);
  stokeslet_tail(xi, yi, zi, s, k, out);
}
#pragma GCC diagnostic pop
#endif

void stokeslet_reference(const Points& x, const SourceArrays& s, Isa isa, Points& u) {
  const int nv = static_cast<int>(x.rows());
#pragma omp parallel for schedule(static)
  for (int i = 0; i < nv; ++i) {
    double acc[3] = {0, 0, 0};
#ifdef BENDLAB_BENCH_X86
    if (isa == kAvx512)
      stokeslet_sum_avx512(x(i, 0), x(i, 1), x(i, 2), s, acc);
    else if (isa == kAvx2)
      stokeslet_sum_avx2(x(i, 0), x(i, 1), x(i, 2), s, acc);
    else
#endif
      stokeslet_sum_baseline(x(i, 0), x(i, 1), x(i, 2), s, acc);
    u(i, 0) = acc[0];
    u(i, 1) = acc[1];
    u(i, 2) = acc[2];
  }
}

void BM_StokesletReference(benchmark::State& state, Isa isa) {
  if (!isa_supported(isa)) {
    state.SkipWithError("instruction set not available on this processor or compiler");
    return;
  }
  const TriMesh& mesh = unit_sphere(static_cast<int>(state.range(0)));
  const int threads = static_cast<int>(state.range(1));
  omp_set_num_threads(threads);
  const SourceArrays sources = source_arrays(mesh, smooth_density(mesh.positions()));
  Points u(mesh.num_vertices(), 3);
  for (auto _ : state) {
    stokeslet_reference(mesh.positions(), sources, isa, u);
    benchmark::DoNotOptimize(u.data());
    benchmark::ClobberMemory();
  }
  set_pair_counters(state, mesh, threads);
}
#define BENDLAB_REFERENCE(isa_name, isa)                       \
  BENCHMARK_CAPTURE(BM_StokesletReference, isa_name, isa)      \
      ->ArgsProduct({{1280, 5120, 20480}, {1, 2}})             \
      ->ArgNames({"triangles", "threads"})                     \
      ->UseRealTime()                                          \
      ->Unit(benchmark::kMillisecond)
BENDLAB_REFERENCE(baseline, kBaseline);
BENDLAB_REFERENCE(avx2, kAvx2);
BENDLAB_REFERENCE(avx512, kAvx512);

// Independent chains acc = acc * a + b held in registers, 2 flops per element and step: 24
// doubles (12 SSE2 registers) for the baseline build, 12 registers of 4 (AVX2 with FMA) and 16 of
// 8 (AVX-512, fused) doubles for the others.
constexpr long kSteps = 1 << 22;

double multiply_add_baseline(double a, double b, double seed) {
  constexpr int chains = 24;
  alignas(64) double acc[chains];
  for (int j = 0; j < chains; ++j) acc[j] = seed + j * 1e-3;
  for (long s = 0; s < kSteps; ++s) {
#pragma omp simd
    for (int j = 0; j < chains; ++j) acc[j] = acc[j] * a + b;
  }
  double total = 0;
  for (int j = 0; j < chains; ++j) total += acc[j];
  return total;
}

#ifdef BENDLAB_BENCH_X86
__attribute__((target("avx2,fma"))) double multiply_add_avx2(double a, double b, double seed) {
  constexpr int chains = 12;
  __m256d acc[chains];
  for (int j = 0; j < chains; ++j) acc[j] = _mm256_set1_pd(seed + j * 1e-3);
  const __m256d va = _mm256_set1_pd(a), vb = _mm256_set1_pd(b);
  for (long s = 0; s < kSteps; ++s)
    for (int j = 0; j < chains; ++j) acc[j] = _mm256_fmadd_pd(acc[j], va, vb);
  alignas(32) double out[4];
  __m256d total = acc[0];
  for (int j = 1; j < chains; ++j) total = _mm256_add_pd(total, acc[j]);
  _mm256_store_pd(out, total);
  return out[0] + out[1] + out[2] + out[3];
}

#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wuninitialized"
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
__attribute__((target("avx512f"))) double multiply_add_avx512(double a, double b, double seed) {
  constexpr int chains = 16;
  __m512d acc[chains];
  for (int j = 0; j < chains; ++j) acc[j] = _mm512_set1_pd(seed + j * 1e-3);
  const __m512d va = _mm512_set1_pd(a), vb = _mm512_set1_pd(b);
  for (long s = 0; s < kSteps; ++s)
    for (int j = 0; j < chains; ++j) acc[j] = _mm512_fmadd_pd(acc[j], va, vb);
  __m512d total = acc[0];
  for (int j = 1; j < chains; ++j) total = _mm512_add_pd(total, acc[j]);
  return _mm512_reduce_add_pd(total);
}
#pragma GCC diagnostic pop
#endif

void BM_MultiplyAddPeak(benchmark::State& state, Isa isa) {
  if (!isa_supported(isa)) {
    state.SkipWithError("instruction set not available on this processor or compiler");
    return;
  }
  const int threads = static_cast<int>(state.range(0));
  omp_set_num_threads(threads);
  double a = 0.999999, b = 1e-7;
  benchmark::DoNotOptimize(a);
  benchmark::DoNotOptimize(b);
  const double doubles = isa == kAvx512 ? 16 * 8 : isa == kAvx2 ? 12 * 4 : 24;
  for (auto _ : state) {
    double total = 0;
#pragma omp parallel reduction(+ : total)
    {
      const double seed = 1.0 + omp_get_thread_num();
#ifdef BENDLAB_BENCH_X86
      if (isa == kAvx512)
        total += multiply_add_avx512(a, b, seed);
      else if (isa == kAvx2)
        total += multiply_add_avx2(a, b, seed);
      else
#endif
        total += multiply_add_baseline(a, b, seed);
    }
    benchmark::DoNotOptimize(total);
  }
  const double flops = 2.0 * doubles * static_cast<double>(kSteps) * threads;
  state.counters["threads"] = threads;
  state.counters["flops_per_s"] = benchmark::Counter(flops, benchmark::Counter::kIsIterationInvariantRate);
  state.counters["flops_per_s_per_thread"] =
      benchmark::Counter(flops / threads, benchmark::Counter::kIsIterationInvariantRate);
}
#define BENDLAB_PEAK(isa_name, isa) \
  BENCHMARK_CAPTURE(BM_MultiplyAddPeak, isa_name, isa)->Arg(1)->Arg(2)->ArgName("threads")->UseRealTime()->Unit(benchmark::kMillisecond)
BENDLAB_PEAK(baseline, kBaseline);
BENDLAB_PEAK(avx2, kAvx2);
BENDLAB_PEAK(avx512, kAvx512);

}  // namespace

BENCHMARK_MAIN();
