// Method S (loop_shell.hpp): where the time of one force evaluation goes, stage by stage, on the
// red blood cell of the paper's section 3, with Method C's `forces` for scale. Processor seconds
// per call (std::clock, all threads: on a shared machine closer to the work done than wall time),
// the median of `repeats` calls alternating between two nearby shapes (as bench_bending's
// BM_Forces does). Not a Google Benchmark: a breakdown, printed as a table.
//
//   loop_shell_stages TRIANGLES [REPEATS (default 5)]
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <ctime>
#include <string>
#include <vector>

#include "bendlab/bending/loop_shell.hpp"
#include "bendlab/bending/loop_shell_assembly.hpp"
#include "bendlab/bending/loop_shell_limit.hpp"
#include "bendlab/bending/loop_shell_solve.hpp"
#include "bendlab/bending/method_registry.hpp"
#include "bendlab/geometry/mesh_geometry.hpp"
#include "bendlab/mesh/generators.hpp"
#include "bendlab/surfaces/analytic_surface.hpp"

using namespace bendlab;
using namespace bendlab::loop_shell;

namespace {

template <class F>
double seconds(F&& f) {
  const std::clock_t t0 = std::clock();
  f();
  return double(std::clock() - t0) / CLOCKS_PER_SEC;
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    fmt::print(stderr, "usage: loop_shell_stages TRIANGLES [REPEATS]\n");
    return 1;
  }
  const int triangles = std::stoi(argv[1]);
  const int repeats = argc > 2 ? std::stoi(argv[2]) : 5;
  const TriMesh sphere = sphere_mesh(MeshFamily::MT1, level_with_triangles(MeshFamily::MT1, triangles));
  const TriMesh mesh = sphere.with_positions(make_rbc()->map_from_unit_sphere(sphere.positions()));
  const Topology& t = mesh.topology();
  Points moved = mesh.positions();
  for (Eigen::Index i = 0; i < moved.rows(); ++i) moved.row(i) *= 1.0 + 1e-3 * std::sin(3.0 * moved(i, 0));
  const Points* shapes[2] = {&mesh.positions(), &moved};

  // Set-up (once per topology).
  LoopPatches patches;
  const double t_patches = seconds([&] { patches = LoopPatches::build(t); });
  std::vector<int> valences(patches.valence.begin(), patches.valence.end());
  std::sort(valences.begin(), valences.end());
  valences.erase(std::unique(valences.begin(), valences.end()), valences.end());
  QuadratureBases* bases = nullptr;
  const double t_bases = seconds([&] { bases = new QuadratureBases(dunavant_rule(6), valences); });
  MassPattern* mass = nullptr;
  const double t_mass_pattern = seconds([&] { mass = new MassPattern(patches, t.num_vertices()); });
  FaceColouring colouring;
  const double t_colouring = seconds([&] { colouring = FaceColouring::build(patches, t.num_vertices()); });
  Eigen::SparseMatrix<double> limit;
  LimitSolver* limit_solver = nullptr;
  const double t_limit_lu = seconds([&] {
    limit = limit_matrix(t);
    limit_solver = new LimitSolver(t);
  });

  // Per call, stage by stage.
  std::vector<double> s_reference, s_control, s_copy, s_assembly, s_solve, s_nodal, s_area, s_total, c_total;
  std::vector<int> iterations;
  Eigen::MatrixXd last;
  const auto c = make_bending_method("C");
  const auto s = make_bending_method("S");
  Points force;
  s->forces(t, moved, 1.0, force);
  for (int r = 0; r < repeats; ++r) {
    const Points& x = *shapes[r % 2];
    Points control, gradient;
    Eigen::SparseMatrix<double> m;
    Eigen::MatrixXd fc;
    s_control.push_back(seconds([&] { control = limit_solver->solve(x); }));
    s_copy.push_back(seconds([&] { m = mass->pattern(); }));
    s_assembly.push_back(
        seconds([&] { shell_energy_mass(patches, *bases, *mass, colouring, control, 1.0, gradient, m); }));
    // The serial reference of the same pass (shell_energy + MassPattern::assemble), for scale.
    s_reference.push_back(seconds([&] {
      Points g;
      shell_energy(patches, *bases, control, 1.0, &g);
      Eigen::SparseMatrix<double> mr = mass->pattern();
      mass->assemble(patches, *bases, control, mr);
    }));
    int it = 0;
    s_solve.push_back(seconds([&] {
      fc = solve_mass_cg(m, -gradient, LoopShellMethod::kCgTolerance, 10000, &it, &last);
      last = fc;
    }));
    iterations.push_back(it);
    Points fd;
    s_nodal.push_back(seconds([&] { fd = limit * fc; }));
    s_area.push_back(seconds([&] { (void)mixed_area(t, x).sum(); }));
    s_total.push_back(seconds([&] { s->forces(t, x, 1.0, force); }));
    c_total.push_back(seconds([&] { c->forces(t, x, 1.0, force); }));
  }
  fmt::print("Method S stages, {} triangles, {} vertices (processor ms per call, median of {})\n", t.num_faces(),
             t.num_vertices(), repeats);
  fmt::print("set-up: patches {:.3f}, quadrature bases {:.3f}, mass pattern {:.3f}, colouring {:.3f} ({} colours), L + LDLT of S {:.3f}\n",
             1e3 * t_patches, 1e3 * t_bases, 1e3 * t_mass_pattern, 1e3 * t_colouring, colouring.num_colours(), 1e3 * t_limit_lu);
  fmt::print("control L P = X {:.3f}\nmass pattern copy {:.3f}\nenergy+gradient+M {:.3f}\n", 1e3 * median(s_control),
             1e3 * median(s_copy), 1e3 * median(s_assembly));
  fmt::print("(reference energy+gradient, then M: {:.3f})\n", 1e3 * median(s_reference));
  fmt::print("CG solve {:.3f} ({} iterations)\nnodal L f_c {:.3f}\nmixed area {:.3f}\n", 1e3 * median(s_solve),
             iterations.back(), 1e3 * median(s_nodal), 1e3 * median(s_area));
  fmt::print("S forces() {:.3f}\nC forces() {:.3f}\nratio {:.1f}\n", 1e3 * median(s_total), 1e3 * median(c_total),
             median(s_total) / median(c_total));
  delete bases;
  delete mass;
  delete limit_solver;
  return 0;
}
