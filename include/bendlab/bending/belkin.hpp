#pragma once
// Method D (paper section 2.4.2): Method C with the Laplace-Beltrami operator replaced by Belkin
// et al.'s heat-kernel discretization, eq. (13).
//
// The operator, with the div-grad sign of CONVENTIONS.md (the paper writes w(x_i) - w(p)):
//
//   (Lap w)_i = 1/(4 pi a_i^2) sum_t A_t/3 sum_{p in V(t)} exp(-|p - x_i|^2 / (4 a_i)) (w(p) - w(x_i))
//
// with a_i = A_mixed_i. The double sum over triangles and their corners is evaluated as the
// equivalent sum over vertices p with the lumped weight A_p = (sum of the areas of the faces at
// p) / 3. Half-space rule of section 2.4.2: only points p strictly above the plane through the
// volume centroid c whose normal points from c to x_i, i.e. (p - c).(x_i - c) > 0, take part, so
// that nodes close in space but far along the surface (the two dimples of a red blood cell) do not
// see each other. Points within a relative margin of 1e-9 of the plane count as on it (see
// belkin.cpp), so that the rule does not depend on rounding for symmetric meshes.
//
// Cost: O(N^2) (every vertex sees every vertex), OpenMP over i. Terms whose exponent
// |p - x_i|^2 / (4 a_i) exceeds 80 are skipped without calling exp: together they change
// (Lap w)_i by at most e^-80 A_total 2 max|w| / (4 pi a_i^2) ~ 3e-36 N max|w| / a_i
// (A_total / a_i ~ N), far below the rounding error of the kept sum for any mesh that fits in
// memory. The operator of a constant is exactly zero (every term carries w(p) - w(x_i) = 0).
#include <memory>
#include <vector>

#include "bendlab/bending/method_registry.hpp"
#include "bendlab/geometry/mesh_geometry.hpp"

namespace bendlab {

struct BelkinOptions {
  /// Apply the half-space rule of section 2.4.2 (the paper's Method D does). Without it the sum
  /// runs over every vertex, as in Belkin et al.'s original operator.
  bool half_space = true;
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

/// The operator above for one shape, prepared once (centred coordinates, lumped weights, a_i)
/// and applied to several fields, as Method D does to x and then to H.
class BelkinLaplacian {
 public:
  BelkinLaplacian(const Topology& topology, const Points& x, const MeshGeometry& geometry,
                  BelkinOptions options = {});
  Scalars apply(const Scalars& w) const;
  Points apply(const Points& w) const;
  /// Lumped weight of vertex p: one third of the area of the faces at p.
  const Scalars& lumped_area() const { return lumped_area_; }

 private:
  template <int Cols>
  void apply_columns(const double* const* w, double* const* out) const;

  BelkinOptions options_;
  int n_ = 0;
  std::vector<double> qx_, qy_, qz_;  ///< positions relative to the volume centroid (SoA)
  std::vector<double> qnorm_;         ///< |x_p - c|
  Scalars lumped_area_;
  Scalars kernel_area_;               ///< a_i = A_mixed_i
};

/// Method D: normal = MWA; H by eq. (2) with eq. (13) (H = -1/2 (Lap x) . n); lapH by eq. (13)
/// applied to H; K by eq. (12); f by eq. (10); F = f A_mixed (eq. (14)); no energy.
class BelkinMethod final : public BendingMethod {
 public:
  explicit BelkinMethod(BelkinOptions options = {}) : options_(options) {}
  /// Method D has no options yet; any option is an error (bendlab::Error naming it).
  static std::unique_ptr<BendingMethod> create(const MethodOptions& options);
  /// The method's entry in the registry (method_registry.hpp): description, options, capabilities.
  static MethodInfo info();

  std::string name() const override { return "D"; }
  BendingResult compute(const Topology& topology, const Points& x, double kappa_b) const override;

 private:
  BelkinOptions options_;
};

}  // namespace bendlab
