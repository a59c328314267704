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

#include "bendlab/core/types.hpp"
#include "bendlab/mesh/topology.hpp"

namespace bendlab {

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
  /// Every per-vertex quantity of the method.
  virtual BendingResult compute(const Topology& topology, const Points& x, double kappa_b) const = 0;
  /// Node forces F only (what a flow solver needs); the default calls compute().
  virtual void forces(const Topology& topology, const Points& x, double kappa_b, Points& force) const {
    force = compute(topology, x, kappa_b).force;
  }
  /// E_B for energy-based methods, std::nullopt otherwise.
  virtual std::optional<double> energy(const Topology&, const Points&, double) const { return std::nullopt; }
};

/// Creates a method by name ("A".."E", "ED", or any method registered since), with its options,
/// through the method table (method_registry.hpp): the options are checked against the method's
/// schema and completed with the defaults. Throws bendlab::Error for an unknown name (listing the
/// known ones) or an option the schema refuses (naming the method and the option).
std::unique_ptr<BendingMethod> make_bending_method(const std::string& name, const MethodOptions& options = {});

}  // namespace bendlab
