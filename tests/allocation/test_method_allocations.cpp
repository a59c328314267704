// Once warm, BendingMethod::compute_into and forces allocate nothing (bending/method_workspace.hpp):
// the same method instance, the same mesh, the same result arrays, for every registered method
// (and with c0 / ADE for those that take them), on one and on two OpenMP threads.
//
// The count: this program defines malloc, calloc, realloc and the aligned allocators, counting
// each call while `armed` and forwarding it to glibc (__libc_malloc and its siblings). The
// executable's definitions come first in the dynamic linker's search, so libstdc++'s operator new,
// Eigen's aligned_malloc, std::vector, std::string and libgomp all reach them: the test sees every
// allocation of the calls it wraps, on every thread (CountingHookSeesEveryAllocator checks that).
// Under AddressSanitizer, which owns malloc, the tests are skipped.
//
// Not counted against the methods: what the OpenMP runtime allocates for itself, told apart by the
// caller's address (inside libgomp). libgomp mallocs and frees a team descriptor (a few hundred
// bytes, from malloc's per-thread cache: no page is ever returned or faulted in) for every
// parallel region of one thread, `if (false)` regions included; with two or more threads it keeps
// its last team. The tests report that count beside the methods' own.
#include <gtest/gtest.h>
#include <link.h>
#include <omp.h>

#include <atomic>
#include <cerrno>
#include <cmath>
#include <cstddef>
#include <cstdlib>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include "bendlab/bending/method_registry.hpp"
#include "bendlab/mesh/generators.hpp"
#include "bendlab/surfaces/analytic_surface.hpp"

#if defined(__SANITIZE_ADDRESS__)
#define BENDLAB_ALLOCATION_HOOK 0
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define BENDLAB_ALLOCATION_HOOK 0
#endif
#endif
#ifndef BENDLAB_ALLOCATION_HOOK
#define BENDLAB_ALLOCATION_HOOK 1
#endif

namespace {
std::atomic<bool> armed{false};
std::atomic<long> allocations{0}, runtime_allocations{0};
// The executable segments of libgomp (found before the first count, by dl_iterate_phdr).
struct Range {
  std::uintptr_t begin = 0, end = 0;
};
Range runtime_code[8];
int runtime_ranges = 0;

int find_runtime(dl_phdr_info* info, std::size_t, void*) {
  if (!info->dlpi_name || !std::strstr(info->dlpi_name, "libgomp")) return 0;
  for (int k = 0; k < info->dlpi_phnum && runtime_ranges < 8; ++k) {
    const ElfW(Phdr)& ph = info->dlpi_phdr[k];
    if (ph.p_type != PT_LOAD || !(ph.p_flags & PF_X)) continue;
    const std::uintptr_t begin = info->dlpi_addr + ph.p_vaddr;
    runtime_code[runtime_ranges++] = {begin, begin + ph.p_memsz};
  }
  return 0;
}

[[gnu::noinline]] void count(const void* caller) {
  if (!armed.load(std::memory_order_relaxed)) return;
  const auto a = reinterpret_cast<std::uintptr_t>(caller);
  for (int k = 0; k < runtime_ranges; ++k)
    if (a >= runtime_code[k].begin && a < runtime_code[k].end) {
      runtime_allocations.fetch_add(1, std::memory_order_relaxed);
      return;
    }
  allocations.fetch_add(1, std::memory_order_relaxed);
}
}  // namespace

#if BENDLAB_ALLOCATION_HOOK
extern "C" {
void* __libc_malloc(std::size_t);
void* __libc_calloc(std::size_t, std::size_t);
void* __libc_realloc(void*, std::size_t);
void* __libc_memalign(std::size_t, std::size_t);

void* malloc(std::size_t n) {
  count(__builtin_return_address(0));
  return __libc_malloc(n);
}
void* calloc(std::size_t n, std::size_t size) {
  count(__builtin_return_address(0));
  return __libc_calloc(n, size);
}
void* realloc(void* p, std::size_t n) {
  count(__builtin_return_address(0));
  return __libc_realloc(p, n);
}
void* memalign(std::size_t alignment, std::size_t n) {
  count(__builtin_return_address(0));
  return __libc_memalign(alignment, n);
}
void* aligned_alloc(std::size_t alignment, std::size_t n) {
  count(__builtin_return_address(0));
  return __libc_memalign(alignment, n);
}
int posix_memalign(void** out, std::size_t alignment, std::size_t n) {
  count(__builtin_return_address(0));
  void* p = __libc_memalign(alignment, n);
  if (!p) return ENOMEM;
  *out = p;
  return 0;
}
}
#endif

using namespace bendlab;

namespace {

// Allocations made by f (on any thread) while it runs, not counting the OpenMP runtime's own
// (left in runtime_allocations).
template <class F>
long allocations_in(F&& f) {
  if (runtime_ranges == 0) dl_iterate_phdr(find_runtime, nullptr);
  allocations = 0;
  runtime_allocations = 0;
  armed = true;
  f();
  armed = false;
  return allocations.load();
}

void* volatile sink;  // what the checks allocate escapes, so the compiler cannot drop the allocation

bool same_bits(const Eigen::Ref<const Eigen::MatrixXd>& a, const Eigen::Ref<const Eigen::MatrixXd>& b) {
  if (a.rows() != b.rows() || a.cols() != b.cols()) return false;
  for (Eigen::Index j = 0; j < a.cols(); ++j)
    for (Eigen::Index i = 0; i < a.rows(); ++i)
      if (std::memcmp(&a.coeffRef(i, j), &b.coeffRef(i, j), sizeof(double)) != 0) return false;
  return true;
}

void expect_same(const BendingResult& a, const BendingResult& b, const std::string& label) {
  EXPECT_TRUE(same_bits(a.force, b.force)) << label << ": force";
  EXPECT_TRUE(same_bits(a.force_density, b.force_density)) << label << ": force_density";
  EXPECT_TRUE(same_bits(a.normal, b.normal)) << label << ": normal";
  EXPECT_TRUE(same_bits(a.H, b.H)) << label << ": H";
  EXPECT_TRUE(same_bits(a.K, b.K)) << label << ": K";
  EXPECT_TRUE(same_bits(a.lapH, b.lapH)) << label << ": lapH";
  EXPECT_TRUE(same_bits(a.area, b.area)) << label << ": area";
  EXPECT_EQ(a.energy.has_value(), b.energy.has_value()) << label << ": energy";
  if (a.energy && b.energy) {
    EXPECT_EQ(*a.energy, *b.energy) << label << ": energy";
  }
}

// The red blood cell at 1280 triangles and a second shape near it, as successive stages of a
// flow run see.
struct Shapes {
  TriMesh mesh = sphere_mesh(MeshFamily::MT1, 3);
  Points x[2];
  Shapes() {
    x[0] = make_rbc()->map_from_unit_sphere(mesh.positions());
    x[1] = x[0];
    for (Eigen::Index i = 0; i < x[1].rows(); ++i) x[1].row(i) *= 1.0 + 1e-3 * std::sin(3.0 * x[1](i, 0));
  }
};

// Every method: warm with one call on each shape, then counted on both.
void expect_no_allocation_once_warm(const BendingParameters& p, int threads) {
  const Shapes s;
  const Topology& t = s.mesh.topology();
  omp_set_num_threads(threads);
  int checked = 0;
  for (const std::string& name : bending_method_names()) {
    const auto method = make_bending_method(name);
    if (!p.plain()) {
      try {
        method->check_parameters(p);
      } catch (const Error&) {
        continue;  // a method without c0 / ADE (A)
      }
    }
    ++checked;
    BendingResult r;
    Points force(t.num_vertices(), 3);
    for (const Points& x : s.x) {
      method->compute_into(t, x, p, r);
      method->forces(t, x, p, force);
    }
    const long in_compute = allocations_in([&] {
      for (const Points& x : s.x) method->compute_into(t, x, p, r);
    });
    const long runtime_compute = runtime_allocations;
    const long in_forces = allocations_in([&] {
      for (const Points& x : s.x) method->forces(t, x, p, force);
    });
    const long runtime_forces = runtime_allocations;
    EXPECT_EQ(in_compute, 0) << "method " << name << ": compute_into allocated, " << threads << " thread(s)";
    EXPECT_EQ(in_forces, 0) << "method " << name << ": forces allocated, " << threads << " thread(s)";
    std::printf("method %-2s, %d thread(s), 2 calls each: compute_into %ld, forces %ld allocations "
                "(OpenMP runtime's own: %ld, %ld)\n",
                name.c_str(), threads, in_compute, in_forces, runtime_compute, runtime_forces);
    // The values are those of compute() on a fresh instance, bit for bit. (S starts its mass solve
    // from the previous solution of its instance, so a fresh one agrees to the solve's tolerance.)
    const BendingResult fresh = make_bending_method(name)->compute(t, s.x[1], p);
    if (name == "S") {
      EXPECT_LT((r.force - fresh.force).norm(), 1e-8 * fresh.force.norm()) << "method S";
      EXPECT_LT((force - fresh.force).norm(), 1e-8 * fresh.force.norm()) << "method S";
      continue;
    }
    expect_same(r, fresh, "method " + name);
    EXPECT_TRUE(same_bits(force, fresh.force)) << "method " << name << ": forces() against compute()";
  }
  EXPECT_GE(checked, p.plain() ? 9 : 8);
  omp_set_num_threads(1);
}

}  // namespace

TEST(MethodAllocations, CountingHookSeesEveryAllocator) {
  if (!BENDLAB_ALLOCATION_HOOK) GTEST_SKIP() << "AddressSanitizer owns malloc";
  EXPECT_EQ(allocations_in([] {
              int* p = new int(1);
              sink = p;
              delete p;
            }),
            1);
  EXPECT_EQ(allocations_in([] {
              std::vector<double> v(1000);
              v.resize(5000);
            }),
            2);
  EXPECT_EQ(allocations_in([] { const Eigen::MatrixXd m = Eigen::MatrixXd::Zero(50, 50); }), 1);
  EXPECT_EQ(allocations_in([] {
              sink = std::malloc(16);
              std::free(sink);
            }),
            1);
  // Allocations on OpenMP's other threads count too.
  omp_set_num_threads(2);
  const long threaded = allocations_in([] {
#pragma omp parallel num_threads(2)
    {
      int* p = new int(omp_get_thread_num());
      sink = p;
      delete p;
    }
  });
  omp_set_num_threads(1);
  EXPECT_GE(threaded, 2);
  // Reusing storage of the right size allocates nothing.
  Eigen::MatrixXd m(40, 3);
  std::vector<int> v(100);
  EXPECT_EQ(allocations_in([&] {
              m.resize(40, 3);
              m.setZero();
              v.assign(100, 1);
            }),
            0);
}

TEST(MethodAllocations, ComputeAndForcesAllocateNothingOnceWarm) {
  if (!BENDLAB_ALLOCATION_HOOK) GTEST_SKIP() << "AddressSanitizer owns malloc";
  expect_no_allocation_once_warm(BendingParameters(1.0), 1);
}

TEST(MethodAllocations, WithSpontaneousCurvatureAndAde) {
  if (!BENDLAB_ALLOCATION_HOOK) GTEST_SKIP() << "AddressSanitizer owns malloc";
  BendingParameters p(1.0);
  p.c0 = 0.5;
  p.ade_alpha = 1.0;
  p.ade_d = 0.02;
  p.ade_area = 12.0;
  expect_no_allocation_once_warm(p, 1);
}

TEST(MethodAllocations, OnTwoThreads) {
  if (!BENDLAB_ALLOCATION_HOOK) GTEST_SKIP() << "AddressSanitizer owns malloc";
  expect_no_allocation_once_warm(BendingParameters(1.0), 2);
}
