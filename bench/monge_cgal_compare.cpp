// Method M (monge_jet.hpp, METHOD_M.md) against CGAL's Monge_via_jet_fitting on the same supports:
// H and K at every node of the red blood cell of the study, their errors against the analytic
// values (eq. (17): |H_a - H| / max|H_a|, likewise K, maximum and mean over the nodes), and the
// time of one fit per vertex. Built only where CGAL is found (CMakeLists.txt); CGAL is an optional
// peer, never a dependency. scripts/make_monge_cgal_doc.py runs it and writes
// docs/results/monge_cgal.md.
//
//   monge_cgal_compare [--repeats R] [--triangles N ...] [--families mt1,irregular]
//
// Output: CSV on stdout, one row per (family, triangles, fit):
//   family,triangles,vertices,fit,valid,max_H,mean_H,max_K,mean_K,us_per_vertex,cpu_us_per_vertex,
//   support_min,support_mean,support_max
// and on stderr a check that the supports are those of monge_jet_fit (M's degree-5 H and K per
// node equal monge_jet_fit's bit for bit).
//
// The supports: for every vertex the vertices monge_jet_fit uses for a degree-5 fit
// (3-ring, widened ring by ring to at least 24 points or until the fit is regular; the ring count
// is read back from monge_jet_fit). Every fit gets the same points:
//   M5, M4, M6  monge_jet_fit_point, degree 5 / 4 / 6 on the degree-5 supports, chart normal =
//               covariance normal of the 2-ring (M6: the method's default degree; the method itself
//               widens supports of fewer than 31 points)
//               signed by the angle-weighted normal (METHOD_M.md step 1); the node is the origin
//               and the jet has no constant term.
//   CGAL4, CGAL5  Monge_via_jet_fitting(d_fitting = 4 / 5, d_monge = 4) on the node followed by the
//               support (CGAL fits a constant term too, so the surface need not pass through the
//               node; its frame is the PCA of all the points).
// CGAL's principal curvatures k1 >= k2 belong to the Monge normal, which is turned to the analytic
// outward normal (comply_wrt_given_normal). CGAL's curvatures are the eigenvalues of I^-1 II with
// II = n . X_uu, so a sphere with outward normal has k1 = k2 = -1/R; docs/conventions.md has H > 0
// there, hence H = -(k1 + k2) / 2 and K = k1 k2.
//
// Timing: single thread, std::chrono::steady_clock over all vertices of a mesh (the points are
// gathered beforehand, the frame of M is part of M's time as the PCA is part of CGAL's), the best
// of R repeats, divided by the number of vertices; beside it the thread's processor time
// (CLOCK_THREAD_CPUTIME_ID) of the same repeat, the steadier figure on a loaded machine.
#include <CGAL/Monge_via_jet_fitting.h>
#include <CGAL/Simple_cartesian.h>
#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <ctime>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "bendlab/analysis/error_measures.hpp"
#include "bendlab/bending/monge_jet.hpp"
#include "bendlab/geometry/mesh_geometry.hpp"
#include "bendlab/mesh/generators.hpp"
#include "bendlab/mesh/neighbourhood.hpp"
#include "bendlab/surfaces/analytic_surface.hpp"

using namespace bendlab;

namespace {

using Kernel = CGAL::Simple_cartesian<double>;
using CgalPoint = Kernel::Point_3;
using CgalVector = Kernel::Vector_3;
using MongeFitting = CGAL::Monge_via_jet_fitting<Kernel>;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

/// Every vertex's support, flattened: positions (node excluded) and, for CGAL, node then support.
struct Supports {
  std::vector<std::size_t> begin;   ///< support of vertex i: [begin[i], begin[i + 1])
  std::vector<int> two_ring;        ///< size of the 2-ring prefix (the covariance frame's points)
  std::vector<Vec3> points;
  std::vector<std::size_t> cgal_begin;
  std::vector<CgalPoint> cgal_points;
};

Supports gather_supports(const Topology& t, const Points& x, const std::vector<MongeJetFit>& fits) {
  Supports s;
  const int n = t.num_vertices();
  VertexRings nb(t);
  s.begin.push_back(0);
  s.cgal_begin.push_back(0);
  for (int i = 0; i < n; ++i) {
    nb.start(i);
    nb.grow_to(2);
    s.two_ring.push_back(static_cast<int>(nb.vertices().size()));
    nb.grow_to(fits[i].rings);
    s.cgal_points.emplace_back(x(i, 0), x(i, 1), x(i, 2));
    for (int v : nb.vertices()) {
      s.points.push_back(x.row(v).transpose());
      s.cgal_points.emplace_back(x(v, 0), x(v, 1), x(v, 2));
    }
    s.begin.push_back(s.points.size());
    s.cgal_begin.push_back(s.cgal_points.size());
  }
  return s;
}

struct FitRun {
  Scalars H, K;
  double seconds = 0;      ///< best of the repeats, whole mesh (steady_clock)
  double cpu_seconds = 0;  ///< the thread's processor time in that repeat
  bool valid = true;
};

double thread_cpu_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}

template <class PerVertex>
FitRun run_fit(int n, int repeats, PerVertex&& per_vertex) {
  FitRun r;
  r.H = Scalars::Constant(n, kNaN);
  r.K = Scalars::Constant(n, kNaN);
  r.seconds = std::numeric_limits<double>::infinity();
  for (int rep = 0; rep < repeats; ++rep) {
    const double c0 = thread_cpu_seconds();
    const auto t0 = std::chrono::steady_clock::now();
    for (int i = 0; i < n; ++i) per_vertex(i, r);
    const auto t1 = std::chrono::steady_clock::now();
    const double c1 = thread_cpu_seconds();
    const double wall = std::chrono::duration<double>(t1 - t0).count();
    if (wall < r.seconds) r.seconds = wall, r.cpu_seconds = c1 - c0;
  }
  for (int i = 0; i < n; ++i) r.valid = r.valid && std::isfinite(r.H[i]) && std::isfinite(r.K[i]);
  return r;
}

std::vector<std::string> split(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream ss(s);
  for (std::string item; std::getline(ss, item, ',');)
    if (!item.empty()) out.push_back(item);
  return out;
}

int usage() {
  fmt::print(stderr, "usage: monge_cgal_compare [--repeats R] [--triangles N ...] [--families mt1,irregular]\n");
  return 2;
}

}  // namespace

int main(int argc, char** argv) {
  int repeats = 3;
  std::vector<long> sizes;
  std::vector<std::string> families = {"mt1", "irregular"};
  for (int a = 1; a < argc; ++a) {
    const std::string arg = argv[a];
    if (arg == "--repeats" && a + 1 < argc) {
      repeats = std::atoi(argv[++a]);
    } else if (arg == "--families" && a + 1 < argc) {
      families = split(argv[++a]);
    } else if (arg == "--triangles") {
      while (a + 1 < argc && argv[a + 1][0] != '-') sizes.push_back(std::atol(argv[++a]));
    } else {
      return usage();
    }
  }
  if (sizes.empty()) sizes = {1280, 5120, 20480, 81920};
  if (repeats < 1) return usage();

  try {
    const auto rbc = make_rbc();
    const SurfaceMaxima maxima = rbc->maxima();
    fmt::print("family,triangles,vertices,fit,valid,max_H,mean_H,max_K,mean_K,us_per_vertex,cpu_us_per_vertex,"
               "support_min,support_mean,support_max\n");
    for (const std::string& family_name : families) {
      const MeshFamily family = parse_mesh_family(family_name);
      for (long triangles : sizes) {
        const int level = level_with_triangles(family, triangles);
        if (level < 0) throw Error(fmt::format("no {} mesh has {} triangles", family_name, triangles));
        const TriMesh unit = sphere_mesh(family, level);
        const Points x = rbc->map_from_unit_sphere(unit.positions());
        const Topology& t = unit.topology();
        const int n = t.num_vertices();
        const MeshGeometry geometry = MeshGeometry::compute(t, x);
        const SurfaceFields exact = rbc->evaluate(x);

        // The supports monge_jet_fit uses (its ring counts), and its own H, K for the check below.
        const std::vector<MongeJetFit> reference = monge_jet_fit(t, x, geometry.normal_mwa, MongeJetSettings{.degree = 5});
        const Supports s = gather_supports(t, x, reference);
        auto support = [&](int i) {
          return std::span<const Vec3>(s.points.data() + s.begin[i], s.begin[i + 1] - s.begin[i]);
        };
        std::size_t smin = std::numeric_limits<std::size_t>::max(), smax = 0, ssum = 0;
        for (int i = 0; i < n; ++i) {
          const std::size_t m = s.begin[i + 1] - s.begin[i];
          smin = std::min(smin, m), smax = std::max(smax, m), ssum += m;
        }

        auto method_m = [&](int degree) {
          return [&, degree](int i, FitRun& r) {
            const Vec3 x0 = x.row(i).transpose();
            const std::span<const Vec3> sup = support(i);
            const Vec3 n0 = covariance_normal(x0, sup.first(s.two_ring[i]), geometry.normal_mwa.row(i).transpose());
            const MongeJetFit f = monge_jet_fit_point(x0, n0, sup, degree);
            r.H[i] = f.valid ? f.H : kNaN;
            r.K[i] = f.valid ? f.K : kNaN;
          };
        };
        auto cgal = [&](int d_fitting) {
          return [&, d_fitting](int i, FitRun& r) {
            MongeFitting fitting;
            const auto b = s.cgal_points.begin() + static_cast<std::ptrdiff_t>(s.cgal_begin[i]);
            const auto e = s.cgal_points.begin() + static_cast<std::ptrdiff_t>(s.cgal_begin[i + 1]);
            MongeFitting::Monge_form form = fitting(b, e, d_fitting, 4);
            const Vec3& na = exact.normal.row(i);
            form.comply_wrt_given_normal(CgalVector(na[0], na[1], na[2]));
            const double k1 = form.principal_curvatures(0), k2 = form.principal_curvatures(1);
            r.H[i] = -0.5 * (k1 + k2);
            r.K[i] = k1 * k2;
          };
        };

        struct Named {
          std::string name;
          FitRun run;
        };
        std::vector<Named> runs;
        runs.push_back({"M5", run_fit(n, repeats, method_m(5))});
        runs.push_back({"M4", run_fit(n, repeats, method_m(4))});
        runs.push_back({"M6", run_fit(n, repeats, method_m(6))});
        runs.push_back({"CGAL4", run_fit(n, repeats, cgal(4))});
        runs.push_back({"CGAL5", run_fit(n, repeats, cgal(5))});

        // The supports are monge_jet_fit's: M5 here must equal it exactly.
        double diff = 0;
        for (int i = 0; i < n; ++i)
          diff = std::max({diff, std::abs(runs[0].run.H[i] - reference[i].H), std::abs(runs[0].run.K[i] - reference[i].K)});
        fmt::print(stderr, "{} {}: {} vertices, support {}-{} points; M5 against monge_jet_fit: max |dH|, |dK| = {:.3g}\n",
                   family_name, triangles, n, smin, smax, diff);
        if (diff != 0) throw Error("the supports differ from monge_jet_fit's");

        for (const Named& r : runs) {
          const ErrorSummary eh = summarize(scalar_errors(exact.H, r.run.H, maxima.H));
          const ErrorSummary ek = summarize(scalar_errors(exact.K, r.run.K, maxima.K));
          fmt::print("{},{},{},{},{},{:.6e},{:.6e},{:.6e},{:.6e},{:.4f},{:.4f},{},{:.3f},{}\n", family_name, triangles,
                     n, r.name, r.run.valid ? 1 : 0, eh.max, eh.average, ek.max, ek.average, 1e6 * r.run.seconds / n,
                     1e6 * r.run.cpu_seconds / n, smin, double(ssum) / n, smax);
        }
        std::fflush(stdout);
      }
    }
  } catch (const std::exception& e) {
    fmt::print(stderr, "monge_cgal_compare: {}\n", e.what());
    return 1;
  }
  return 0;
}
