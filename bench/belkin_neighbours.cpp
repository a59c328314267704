// Method D's heat-kernel operator (belkin.hpp): the O(N) grid form against the O(N^2) reference
// on the red blood cell of the study, with Method C for scale: the time of one force evaluation
// each (processor seconds), and the grid form's relative difference (max norm) from the
// reference, per kernel cut-off. Not a Google Benchmark: single runs (the reference is slow at
// 81920 triangles).
//
//   belkin_neighbours TRIANGLES [CUTOFF ...] [skip-all]   (CUTOFF default 1e-15; skip-all: no reference)
//   belkin_neighbours scaling [TRIANGLES ...]             (default 5120 20480 81920)
//   belkin_neighbours stages [TRIANGLES ...]              (default 5120 20480 81920)
// The second form times Method C and Method D (grid, default cutoff) per size, each the best of
// three evaluations, and prints D's time per vertex (constant for O(N)) and the ratio D / C. Run it
// with OMP_NUM_THREADS=1 for the one-thread ratio. The third times the parts of Method D (best of
// five each): the mesh geometry, the operator's set-up, Lap x and Lap of a scalar field.
// On a machine where first touch of fresh memory is slow (a virtual machine: 17 us per 4 KiB
// page measured), what glibc returns to the system between evaluations, which depends on what the
// other method freed, can dominate either time; set MALLOC_TRIM_THRESHOLD_=4000000000
// MALLOC_MMAP_THRESHOLD_=4000000000 to keep freed memory (belkin.hpp).
#include <fmt/format.h>

#include <algorithm>
#include <ctime>
#include <memory>
#include <string>
#include <vector>

#include "bendlab/bending/belkin.hpp"
#include "bendlab/bending/bending_method.hpp"
#include "bendlab/mesh/generators.hpp"
#include "bendlab/surfaces/analytic_surface.hpp"

using namespace bendlab;

namespace {
// Processor time (all threads): on a shared machine closer to the work done than the wall time.
template <class F>
double seconds(F&& f) {
  const std::clock_t t0 = std::clock();
  f();
  return double(std::clock() - t0) / CLOCKS_PER_SEC;
}
double rel(const Points& a, const Points& ref) { return (a - ref).cwiseAbs().maxCoeff() / ref.cwiseAbs().maxCoeff(); }
}  // namespace

int scaling(const std::vector<long>& sizes) {
  const auto c = make_bending_method("C");
  const auto d = make_bending_method("D");
  for (long triangles : sizes) {
    const TriMesh m = sphere_mesh(MeshFamily::MT1, level_with_triangles(MeshFamily::MT1, triangles));
    const Points x = make_rbc()->map_from_unit_sphere(m.positions());
    double tc = 1e300, td = 1e300;
    for (int rep = 0; rep < 3; ++rep) {
      BendingResult r;
      tc = std::min(tc, seconds([&] { r = c->compute(m.topology(), x, 1.0); }));
      td = std::min(td, seconds([&] { r = d->compute(m.topology(), x, 1.0); }));
    }
    fmt::print("triangles {:6d} vertices {:6d} | C {:.4f} s | D {:.4f} s, {:.3f} us per vertex | D / C {:.2f}\n",
               m.num_faces(), m.num_vertices(), tc, td, 1e6 * td / m.num_vertices(), td / tc);
  }
  return 0;
}

// The stages of one Method D evaluation (best of five each): the mesh geometry, the operator's
// set-up (neighbour lists), its application to x (apply_to_positions) and to a scalar field (as to H).
int stages(const std::vector<long>& sizes) {
  for (long triangles : sizes) {
    const TriMesh m = sphere_mesh(MeshFamily::MT1, level_with_triangles(MeshFamily::MT1, triangles));
    const Points x = make_rbc()->map_from_unit_sphere(m.positions());
    double tg = 1e300, tb = 1e300, tx = 1e300, th = 1e300, td = 1e300;
    const auto d = make_bending_method("D");
    for (int rep = 0; rep < 5; ++rep) {
      td = std::min(td, seconds([&] { d->compute(m.topology(), x, 1.0); }));
      MeshGeometry g;
      tg = std::min(tg, seconds([&] { g = MeshGeometry::compute(m.topology(), x); }));
      std::unique_ptr<BelkinLaplacian> lap;
      tb = std::min(tb, seconds([&] { lap = std::make_unique<BelkinLaplacian>(m.topology(), x, g); }));
      Points lx;
      tx = std::min(tx, seconds([&] { lx = lap->apply_to_positions(); }));
      const Scalars H = lx.col(0);
      th = std::min(th, seconds([&] { lap->apply(H); }));
    }
    fmt::print("triangles {:6d} | geometry {:.4f} s | set-up {:.4f} s | apply x {:.4f} s | apply H {:.4f} s | Method D {:.4f} s\n",
               m.num_faces(), tg, tb, tx, th, td);
  }
  return 0;
}

int main(int argc, char** argv) {
  if (argc >= 2 && std::string(argv[1]) == "stages") {
    std::vector<long> sizes;
    for (int k = 2; k < argc; ++k) sizes.push_back(std::stol(argv[k]));
    if (sizes.empty()) sizes = {5120, 20480, 81920};
    return stages(sizes);
  }
  if (argc >= 2 && std::string(argv[1]) == "scaling") {
    std::vector<long> sizes;
    for (int k = 2; k < argc; ++k) sizes.push_back(std::stol(argv[k]));
    if (sizes.empty()) sizes = {5120, 20480, 81920};
    return scaling(sizes);
  }
  if (argc < 2) {
    fmt::print(stderr, "usage: {} TRIANGLES [CUTOFF ...] [skip-all]\n", argv[0]);
    return 2;
  }
  const long triangles = std::stol(argv[1]);
  std::vector<double> cutoffs;
  bool skip_all = false;
  for (int k = 2; k < argc; ++k) {
    if (std::string(argv[k]) == "skip-all")
      skip_all = true;
    else
      cutoffs.push_back(std::stod(argv[k]));
  }
  if (cutoffs.empty()) cutoffs.push_back(1e-15);
  const TriMesh m = sphere_mesh(MeshFamily::MT1, level_with_triangles(MeshFamily::MT1, triangles));
  const Points x = make_rbc()->map_from_unit_sphere(m.positions());
  BendingResult ref;
  const auto c = make_bending_method("C");
  BendingResult rc;
  const double tc = seconds([&] { rc = c->compute(m.topology(), x, 1.0); });
  fmt::print("triangles {} vertices {} | method C {:.3f} s\n", m.num_faces(), m.num_vertices(), tc);
  if (!skip_all) {
    BelkinOptions all;
    all.neighbours = BelkinOptions::Neighbours::all;
    const double ta = seconds([&] { ref = BelkinMethod(all).compute(m.topology(), x, 1.0); });
    fmt::print("  D neighbours=all {:.3f} s\n", ta);
  }
  for (double cut : cutoffs) {
    BelkinOptions grid;
    grid.kernel_cutoff = cut;
    BendingResult r;
    const double tg = seconds([&] { r = BelkinMethod(grid).compute(m.topology(), x, 1.0); });
    fmt::print("  D neighbours=grid kernel_cutoff={:g} {:.3f} s", cut, tg);
    if (!skip_all)
      fmt::print(" | rel. diff f {:.2e} H {:.2e}", rel(r.force_density, ref.force_density),
                 (r.H - ref.H).cwiseAbs().maxCoeff() / ref.H.cwiseAbs().maxCoeff());
    fmt::print("\n");
  }
  return 0;
}
