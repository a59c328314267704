#pragma once
// The one small interface every bending algorithm implements (paper table 1).
//
// Given a mesh (topology + positions) and the bending modulus kB, a method returns per-vertex
// arrays in vertex order. Signs follow docs/conventions.md:
//   H > 0 on a sphere, lapH = div grad H, f = 2 kB (lapH + 2 H (H^2 - K)) n  (eq. (10)),
//   F = -dE/dx for energy-based methods, and F = f * A_mixed, f = F / A_mixed (eq. (14)).
// Quantities a method does not define are NaN (e.g. H, K, lapH for Method A).
#include <map>
#include <memory>
#include <optional>
#include <string>

#include "bendlab/bending/bending_parameters.hpp"
#include "bendlab/core/types.hpp"
#include "bendlab/mesh/topology.hpp"

namespace bendlab {

/// Below this many faces a call of the per-face kernels (Methods A, B, J) takes a few
/// microseconds, and starting OpenMP threads would cost more than it saves.
inline constexpr int kBendingParallelMinFaces = 4096;

struct BendingResult {
  Points normal;          ///< N x 3, unit outward normal the method uses (NaN if none)
  Scalars H;              ///< N, mean curvature
  Scalars K;              ///< N, Gaussian curvature
  Scalars lapH;           ///< N, Laplace-Beltrami of H
  Points force;           ///< N x 3, node force F
  Points force_density;   ///< N x 3, force density f
  Scalars area;           ///< N, Meyer's mixed area used for the F <-> f conversion
  std::optional<double> energy;  ///< E_B where the method derives from an energy (A, B)
};

/// Method options by name, as given on a command line: {"rings", "2"}, {"small_angle", "true"}.
using MethodOptions = std::map<std::string, std::string>;

class BendingMethod {
 public:
  virtual ~BendingMethod() = default;
  /// Short name: "A", "B", "C", "D", "E", "ED", "S", "J".
  virtual std::string name() const = 0;
  /// Vertex evaluations, since the method was made, where it fell back to a simpler rule than its
  /// own (Method M: a jet of lower degree where the support did not determine the jet); 0 for the
  /// methods without a fallback. Runs report it (summary.json's bending_fallbacks).
  virtual long fallback_count() const { return 0; }
  /// Every per-vertex quantity of the method.
  virtual BendingResult compute(const Topology& topology, const Points& x, double kappa_b) const = 0;
  /// The same into `out`, whose arrays are reused: the built-in methods allocate nothing once warm
  /// (the same instance, mesh and `out` as the call before; method_workspace.hpp), the values are
  /// those of compute() bit for bit. The default assigns compute()'s result.
  virtual void compute_into(const Topology& topology, const Points& x, double kappa_b, BendingResult& out) const {
    out = compute(topology, x, kappa_b);
  }
  /// Node forces F only (what a flow solver needs); the default calls compute(). The built-in
  /// methods allocate nothing once warm (same instance and mesh, `force` already N x 3).
  virtual void forces(const Topology& topology, const Points& x, double kappa_b, Points& force) const {
    force = compute(topology, x, kappa_b).force;
  }
  /// E_B for energy-based methods, std::nullopt otherwise.
  virtual std::optional<double> energy(const Topology&, const Points&, double) const { return std::nullopt; }

  // With spontaneous curvature and ADE (bending_parameters.hpp, docs/conventions.md §5). For
  // plain parameters (c0 = 0, no ADE) these call the functions above, so the results are those
  // of the paper's methods bit for bit; otherwise they validate the parameters and call the
  // *_terms hooks, which refuse (bendlab::Error naming the method) unless the method overrides them.

  /// Every per-vertex quantity with the energy of `p`.
  BendingResult compute(const Topology& topology, const Points& x, const BendingParameters& p) const;
  /// The same into `out` (see compute_into above).
  void compute_into(const Topology& topology, const Points& x, const BendingParameters& p, BendingResult& out) const;
  /// Node forces only.
  void forces(const Topology& topology, const Points& x, const BendingParameters& p, Points& force) const;
  /// E = 2 kB ∫ (H - c0)^2 dA + E_ADE for energy-based methods, std::nullopt otherwise.
  std::optional<double> energy(const Topology& topology, const Points& x, const BendingParameters& p) const;
  /// Throws bendlab::Error (one line, naming the method) if the method cannot take `p`: invalid
  /// parameters, or c0 / ADE for a method without them. Cheap: call it before a long run.
  void check_parameters(const BendingParameters& p) const;

 protected:
  /// Whether the method implements c0 and ADE (the *_terms hooks below).
  virtual bool supports_membrane_terms() const { return false; }
  /// Why not, for the error message (docs/conventions.md §5).
  virtual std::string membrane_terms_refusal() const;
  virtual BendingResult compute_terms(const Topology& topology, const Points& x, const BendingParameters& p) const;
  /// Default: out = compute_terms(...).
  virtual void compute_terms_into(const Topology& topology, const Points& x, const BendingParameters& p,
                                  BendingResult& out) const {
    out = compute_terms(topology, x, p);
  }
  /// Default: compute_terms(...).force.
  virtual void forces_terms(const Topology& topology, const Points& x, const BendingParameters& p,
                            Points& force) const {
    force = compute_terms(topology, x, p).force;
  }
  virtual std::optional<double> energy_terms(const Topology&, const Points&, const BendingParameters&) const {
    return std::nullopt;
  }
};

/// Creates a method by name ("A".."E", "ED", or any method registered since), with its options,
/// through the method table (method_registry.hpp): the options are checked against the method's
/// schema and completed with the defaults. Throws bendlab::Error for an unknown name (listing the
/// known ones) or an option the schema refuses (naming the method and the option).
std::unique_ptr<BendingMethod> make_bending_method(const std::string& name, const MethodOptions& options = {});

}  // namespace bendlab
