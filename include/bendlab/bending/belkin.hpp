#pragma once
// Method D (paper section 2.4.2): Method C with the Laplace-Beltrami operator replaced by Belkin
// et al.'s heat-kernel discretization, eq. (13).
//
// The operator, with the div-grad sign of docs/conventions.md (the paper writes w(x_i) - w(p)):
//
//   (Lap w)_i = 1/(4 pi a_i^2) sum_t A_t/3 sum_{p in V(t)} exp(-|p - x_i|^2 / (4 a_i)) (w(p) - w(x_i))
//
// with a_i = A_mixed_i. The double sum over triangles and their corners is evaluated as the
// equivalent sum over vertices p with the lumped weight A_p = (sum of the areas of the faces at
// p) / 3. Half-space rule of section 2.4.2: only points p strictly above the plane through the
// volume centroid c whose normal points from c to x_i, i.e. (p - c).(x_i - c) > 0, take part, so
// that nodes close in space but far along the surface (the two dimples of a red blood cell) do not
// see each other. Points within a relative margin of 1e-9 of the plane count as on it (see
// belkin_kernel.hpp), so that the rule does not depend on rounding for symmetric meshes.
//
// Two evaluations of the same sum (BelkinOptions::neighbours, method option "neighbours"):
//
// - all (the O(N^2) reference): every vertex sees every vertex, OpenMP over i. Terms whose exponent
//   |p - x_i|^2 / (4 a_i) exceeds 80 are skipped: together they change (Lap w)_i by at most
//   e^-80 A_total 2 max|w| / (4 pi a_i^2) ~ 3e-36 N max|w| / a_i (A_total / a_i ~ N), far below
//   the rounding error of the kept sum for any mesh that fits in memory.
// - grid (the default, O(N)): terms whose kernel weight exp(-|p - x_i|^2 / (4 a_i)) is below
//   kernel_cutoff (method option "kernel_cutoff", default 1e-15) are dropped, so vertex i only
//   sees the points within r_i = sqrt(4 a_i ln(1 / kernel_cutoff)), found through a uniform grid
//   of cells (a cell list sorted by cell; cell sizes below). With a_i ~ A_total / N the
//   ball holds about 4 pi ln(1/cutoff) vertices (about 430 at the default) whatever N: O(N).
//   The neighbour lists (for each vertex, the runs of cell-sorted points, one per row of cells
//   meeting its ball; cells 0.35 median r_i across the rows and half that along them) are built
//   once per shape, when the operator is constructed, and serve every apply() (Method D applies
//   it to x, apply_to_positions(), and to H).
//   Truncation error: each of the at most N dropped terms has weight A_p * exp(-exponent) <=
//   A_p * cutoff and |w(p) - w(x_i)| <= 2 max|w|, so (Lap w)_i changes by at most
//       cutoff * (sum of the dropped A_p) * 2 max|w| / (4 pi a_i^2)
//     <= cutoff * A_total * 2 max|w| / (4 pi a_i^2)  ~  cutoff * N * max|w| / (2 pi a_i)
//   (A_total / a_i ~ N); for the 5120-triangle red blood cell (A_total = 8.76, a_i >= 1.3e-3)
//   that is at most 1e-15 * 8.76 * 2 / (4 pi 1.8e-6) ~ 8e-10 max|w|, against max|Lap x| =
//   2 max|H| = 4.4. In practice far less (the dropped weights decay like a Gaussian beyond r_i).
//   Measured max-norm differences from the reference, relative, for Method D's f on the red blood
//   cell (bench/belkin_neighbours TRIANGLES): 3e-14 (1280 triangles), 2.9e-13 (5120), 1.7e-12
//   (20480), 1.8e-11 (81920); H within 1.1e-13 at every size. (The cut-off alone, with the
//   reference's exponential: 7.5e-12 at 81920; with cutoff 1e-12: 5.9e-9, too close to 1e-8.)
//   Values below e^-80 are clamped to e^-80, the reference's own cut, so that both forms keep the
//   same terms and differ only by the order of the sum and the exponential below.
// Kernels (belkin_kernel.hpp), branch-free over blocks of points of a run (the exponent, the cut-off,
// the run's end and the half-space test as a mask) so that they vectorise (AVX-512, AVX2 or
// baseline, chosen at run time):
// - all: blocks of 16, exp by a polynomial within an ulp of std::exp (measured over [0, 80]).
// - grid: blocks of one vector register (8 with AVX-512, else 4: the runs are short), the
//   exponential in base 2 by a polynomial of degree 9 evaluated by Estrin's scheme (relative
//   error within 2.3e-14), the half-space test only for vertices
//   whose ball crosses the plane (elsewhere every point of the ball passes it: the same terms),
//   and for Lap x the differences p - x_i the distance is made of.
// One Method D evaluation on the red blood cell, one thread, processor time on the shared 2-core
// machine, best of three, D and C timed in turn, with glibc keeping freed memory:
//   MALLOC_TRIM_THRESHOLD_=4000000000 MALLOC_MMAP_THRESHOLD_=4000000000 OMP_NUM_THREADS=1
//   build/release/belkin_neighbours scaling   (one command line)
// 5120 / 20480 / 81920 triangles: D 0.0039 / 0.0155 / 0.063-0.070 s (1.5-1.7 us per vertex,
// linear), C 0.0004 / 0.0020-0.0024 / 0.0087-0.0099 s: D / C 8.8-9.5 / 6.4-7.6 / 7.0-7.4. The
// previous kernel (cubic cells, one kernel for both forms), same command, same time: D 0.110-0.115
// s, 10.4-10.9 times C; before the lists were kept and the loop vectorised: 0.55 to 0.60 s. The
// all-pairs reference: 3.8 s. bench_bending's BM_Forces (repeated evaluations, processor time)
// agrees: D / C 10 / 9.0 / 7.1 (3.97 / 15.6 / 67.0 ms against 0.39 / 1.73 / 9.49 ms). The parts of
// D at 81920 triangles (belkin_neighbours stages 81920, memory kept): mesh geometry 0.008 s (as
// C's), set-up 0.013 s, Lap x 0.022 s, Lap H 0.020 s.
// On an AMD EPYC with AVX2 and no AVX-512 (4 lanes), same command: D 0.0096 / 0.034 / 0.134 s
// (3.3-3.8 us per vertex), C 0.0005 / 0.0026 / 0.0106 s, D / C 18 / 13 / 12.7; stages at 81920:
// geometry 0.009 s, set-up 0.016 s, Lap x 0.058 s, Lap H 0.055 s (the kernel there costs 2.6 times
// the AVX-512 machine's; before Estrin's scheme, 4 lanes and FMA: Lap x 0.084 s, Lap H 0.078 s).
// Kept weights (BelkinOptions::weight_cache_bytes; the construction sums Lap x while it writes the
// weights, Lap H reads them; the buffer reused from shape to shape), same machine and command, old
// and new binary in turn: D 0.0067-0.0081 / 0.026-0.030 / 0.104-0.111 s (2.5-3.2 us per vertex)
// against 0.0096 / 0.034 / 0.135 s before, D / C 8.9-12.8 at every size; without the two
// variables D 0.0078 / 0.027 / 0.106-0.112 s against 0.0101 / 0.037 / 0.146 s. Stages at 81920:
// set-up with the weights and Lap x 0.079 s, Lap H 0.016 s (a read of the 160 MB of weights). The
// 5x of Method C is not reached: the exponentials alone (the weights pass) cost 6 times C there.
// Without the two variables the same run is not a measure of D: first touch of fresh memory costs
// 17 us per 4 KiB page on that virtual machine, and what glibc hands back between evaluations
// depends on what the other method freed. Measured there: with this code C 0.041-0.060 s after D
// (D 0.122-0.167 s, ratio 2.7-3.0), with the previous code C 0.011-0.016 s (D 0.19-0.23 s, ratio
// 14-18); the C code is the same.
// Both are deterministic; they differ only by the order of the sum, the exponential and the
// dropped terms.
// The operator of a constant is exactly zero in both (every term carries w(p) - w(x_i) = 0).
// Where the parts are: belkin_kernel.hpp/.cpp the per-vertex sums and their exponentials;
// belkin_grid.cpp the cell list, the runs, the kept weights and the grid form's applies;
// belkin_reference.cpp the all-pairs form; belkin.cpp the operator's set-up for a shape, the
// dispatch of the applies and Method D.
#include <memory>
#include <vector>

#include "bendlab/bending/method_registry.hpp"
#include "bendlab/bending/variational_assembly.hpp"
#include "bendlab/geometry/mesh_geometry.hpp"

namespace bendlab {

struct BelkinOptions {
  /// Apply the half-space rule of section 2.4.2 (the paper's Method D does). Without it the sum
  /// runs over every vertex, as in Belkin et al.'s original operator.
  bool half_space = true;
  enum class Neighbours { all, grid };
  /// all: the O(N^2) reference sum; grid: the truncated O(N) sum through a cell list.
  Neighbours neighbours = Neighbours::grid;
  /// grid only: kernel weights exp(-|p - x_i|^2 / (4 a_i)) below this are dropped (header comment).
  double kernel_cutoff = 1e-15;
  /// grid only: the kernel weights of the shape (one per point a vertex scans, 8 bytes each) are
  /// computed once, when the operator is constructed, and kept for every apply() when they take at
  /// most this many bytes (about 4 kB a vertex at the default cut-off); above it (or 0) every
  /// apply() computes them again. Either way the same terms in the same order. Each thread keeps
  /// the largest weight buffer it has released for the next shape (~BelkinLaplacian).
  std::size_t weight_cache_bytes = std::size_t{1} << 30;
};

/// Belkin's heat-kernel Laplace-Beltrami, eq. (13), div-grad sign, with a_i = mixed area and the
/// half-space rule of section 2.4.2 (only points p with (p - c).(x_i - c) > 0, c the volume
/// centroid), O(N^2) reference form. `geometry` must be MeshGeometry::compute(topology, x).
Scalars belkin_laplacian(const Topology& topology, const Points& x, const MeshGeometry& geometry, const Scalars& w);
/// The same operator applied to each column of a per-vertex vector field (e.g. positions).
Points belkin_laplacian(const Topology& topology, const Points& x, const MeshGeometry& geometry, const Points& w);
/// Both forms with explicit options (e.g. without the half-space rule).
Scalars belkin_laplacian(const Topology& topology, const Points& x, const MeshGeometry& geometry, const Scalars& w,
                         const BelkinOptions& options);
Points belkin_laplacian(const Topology& topology, const Points& x, const MeshGeometry& geometry, const Points& w,
                        const BelkinOptions& options);

/// The operator above for one shape, prepared once (centred coordinates, lumped weights, a_i and,
/// for the grid form, the cell list) and applied to several fields, as Method D does to x and H.
class BelkinLaplacian {
 public:
  /// An operator for no shape yet (prepare() gives it one).
  BelkinLaplacian() = default;
  BelkinLaplacian(const Topology& topology, const Points& x, const MeshGeometry& geometry,
                  BelkinOptions options = {});
  /// Hands the weights' memory to a spare kept per thread, which the next operator built on that
  /// thread reuses when it is large enough (fresh pages cost more to touch than the sums take).
  ~BelkinLaplacian();
  BelkinLaplacian(BelkinLaplacian&&) = default;
  BelkinLaplacian& operator=(BelkinLaplacian&&) = default;
  /// The operator of another shape (what the constructor does), in this operator's buffers: no
  /// allocation once they are large enough (a method keeps its operator from call to call).
  void prepare(const Topology& topology, const Points& x, const MeshGeometry& geometry, BelkinOptions options = {});
  Scalars apply(const Scalars& w) const;
  Points apply(const Points& w) const;
  /// Lap x: the operator applied to the positions it was built from (equal to apply(x) up to
  /// rounding; the grid form reuses the differences p - x_i its kernel computes anyway).
  Points apply_to_positions() const;
  /// The same three into `out` (resized), with the operator's own scratch buffers: the same values,
  /// no allocation once warm, but not for concurrent use of one operator (apply() is).
  void apply_into(const Scalars& w, Scalars& out);
  void apply_into(const Points& w, Points& out);
  void apply_to_positions_into(Points& out);
  /// Lumped weight of vertex p: one third of the area of the faces at p.
  const Scalars& lumped_area() const { return lumped_area_; }

 private:
  template <int Cols>
  void apply_columns(const double* const* w, double* const* out, std::vector<double>& buffer) const;
  void apply_grid(const double* w, double* const* out, std::vector<double>& buffer) const;
  void build_grid();
  void cache_weights();
  /// Array j of the points in scan order (0, 1, 2: centred position; 3: |x_p - c|; 4: lumped
  /// area), 64-byte aligned, padded by zeros.
  const double* point_array(int j) const;

  BelkinOptions options_;
  int n_ = 0;
  std::vector<double> qx_, qy_, qz_;  ///< positions relative to the volume centroid (SoA)
  std::vector<double> qnorm_;         ///< |x_p - c|
  Scalars lumped_area_;
  Scalars kernel_area_;               ///< a_i = A_mixed_i
  double max_exponent_ = 80;  ///< -ln(kernel_cutoff), at most 80 (the reference: 80)
  // The grid form: cells of sides cell_[0..2] from lo_, dims_[0] x dims_[1] x dims_[2], x fastest.
  double cell_[3] = {0, 0, 0};
  double lo_[3] = {0, 0, 0};
  int dims_[3] = {1, 1, 1};
  // The points in scan order (grid: sorted by cell; reference: vertex order): order_[k] is the
  // vertex at position k, point_array its data. Vertex i scans the runs [runs_[r], runs_[r + 1])
  // for r in [run_start_[i], run_start_[i + 1]) step 2 (run_shared_: every vertex the one run
  // runs_[0..1]).
  std::vector<int> order_, run_start_, runs_;
  bool run_shared_ = false;
  std::size_t stride_ = 0;        ///< distance between the point arrays in points_
  std::vector<double> points_;    ///< the five point arrays (point_array)
  /// Grid form: 1 where vertex i's ball crosses the half-space plane (the kernel tests each
  /// point), 0 where every point within its cut-off radius lies above it.
  std::vector<unsigned char> plane_test_;
  /// Grid form, when they fit options.weight_cache_bytes (else has_weights_ is false): the kernel
  /// weights A_p exp(-|p - x_i|^2 / (4 a_i)) of every lane of every block vertex i scans (zero
  /// where a term is dropped), from weight_start_[i], so that Lap x and Lap H evaluate each
  /// exponential once. The buffer is kept from shape to shape.
  struct WeightBuffer {
    std::unique_ptr<double[]> data;
    std::size_t capacity = 0;
  };
  WeightBuffer weights_;
  bool has_weights_ = false;
  std::vector<std::size_t> weight_start_;
  /// Lap x, summed in the same pass as the weights (apply_to_positions() returns it then).
  Points lap_positions_;
  /// build_grid's buffers, kept from shape to shape: cut-off radii, cell of each point, cell
  /// starts, fill positions, each thread's runs.
  struct GridBuffers {
    std::vector<double> radius, sorted;
    std::vector<int> cell_of, cell_start, fill;
    std::vector<std::vector<int>> parts;
  };
  GridBuffers grid_buffers_;
  /// The *_into functions' buffers: a field in scan order, column-major copies of a vector field.
  std::vector<double> field_buffer_;
  Eigen::MatrixXd columns_in_, columns_out_;
  Points positions_buffer_;
};

/// Method D: normal = MWA; H by eq. (2) with eq. (13) (H = -1/2 (Lap x) . n); lapH by eq. (13)
/// applied to H; K by eq. (12); f by eq. (10); F = f A_mixed (eq. (14)); no energy.
class BelkinMethod final : public VariationalMethod {
 public:
  explicit BelkinMethod(BelkinOptions options = {});
  ~BelkinMethod() override;
  /// Options: "neighbours" = "grid" (default) | "all", "kernel_cutoff" = a number in [1e-300, 0.5]
  /// (default 1e-15); see BelkinOptions. Any other option is an error (bendlab::Error naming it).
  static std::unique_ptr<BendingMethod> create(const MethodOptions& options);
  /// The method's entry in the registry (method_registry.hpp): description, options, capabilities.
  static MethodInfo info();
  const BelkinOptions& options() const { return options_; }

  std::string name() const override { return "D"; }

 protected:
  /// n, H, K, lapH and the mixed area; eq. (10) and c0 / ADE are VariationalMethod's.
  void fields(const Topology& topology, const Points& x, BendingResult& out) const override;

 private:
  BelkinOptions options_;
  struct Workspace;
  /// The geometry, the operator (cell list, weights) and Lap x of the last call, kept between calls.
  MethodWorkspace<Workspace> workspace_;
};

}  // namespace bendlab
