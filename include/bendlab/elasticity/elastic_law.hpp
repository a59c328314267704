#pragma once
// The in-plane elastic law of a capsule membrane (paper section 4.2): an energy E_S(x) of the node
// positions relative to a reference state fixed at construction, and its exact nodal forces
// F = -dE_S/dx. The neo-Hookean law (eqs. (18)-(21), bendlab/elasticity/neo_hookean.hpp) and the
// Skalak law (bendlab/elasticity/skalak.hpp) implement it; make_elastic_law() names them.
//
// Implementations are immutable after construction and their const methods are safe to call
// concurrently (scratch is allocated per call).
#include <memory>
#include <string>
#include <vector>

#include "bendlab/core/types.hpp"
#include "bendlab/mesh/topology.hpp"

namespace bendlab {

class ElasticLaw {
 public:
  virtual ~ElasticLaw() = default;
  /// "neo-Hookean", ...
  virtual std::string name() const = 0;
  /// The in-plane modulus kS of the law (docs/conventions.md §2).
  virtual double kS() const = 0;
  virtual const Topology& topology() const = 0;
  /// E_S for node positions x (N x 3).
  virtual double energy(const Points& x) const = 0;
  /// F = -dE_S/dx into `force` (resized to N x 3, overwritten).
  virtual void forces(const Points& x, Points& force) const = 0;
  /// Both in one pass; returns E_S.
  virtual double energy_and_forces(const Points& x, Points& force) const = 0;
};

/// The reference state shared by the laws on flat linear triangles: per face the reference area
/// a0 and the inverse reference metric (m00, m01, m11) of the edges e1 = x1 - x0, e2 = x2 - x0.
/// Throws bendlab::Error naming `law` for a reference of the wrong size or a zero-area triangle.
void flat_triangle_reference(const Topology& topology, const Points& reference, const char* law, Scalars& a0,
                             Scalars& m00, Scalars& m01, Scalars& m11);

/// force.row(i) = -(sum over the faces of vertex i of dE/dx_i), from the per-face gradients with
/// respect to corners 1 and 2 (grad1, grad2; corner 0's is minus their sum). Gathered per vertex
/// over its one-ring (CSR), so no two threads write one vertex.
void gather_corner_gradients(const Topology& topology, const Points& grad1, const Points& grad2, Points& force);

/// The names make_elastic_law() accepts: {"neo-hookean", "skalak"}.
std::vector<std::string> elastic_law_names();

/// Skalak's C when none is given (area modulus 3 Gs, as the neo-Hookean law's at small strain).
inline constexpr double kDefaultSkalakC = 1.0;

/// The law `name` with reference state (topology, reference positions) and modulus kS;
/// `skalak_c` is the Skalak law's C (ignored by the neo-Hookean law). Throws bendlab::Error for an
/// unknown name, kS <= 0, C <= -1/2 (Skalak) or a degenerate reference triangle.
std::unique_ptr<ElasticLaw> make_elastic_law(const std::string& name, TopologyPtr topology, const Points& reference,
                                             double kS, double skalak_c = kDefaultSkalakC);

}  // namespace bendlab
