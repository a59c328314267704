#pragma once
// The in-plane elastic law of a capsule membrane (paper section 4.2): an energy E_S(x) of the node
// positions relative to a reference state fixed at construction, and its exact nodal forces
// F = -dE_S/dx. The neo-Hookean law (eqs. (18)-(21), bendlab/elasticity/neo_hookean.hpp) is one
// implementation; a Skalak law adds another file and one name in make_elastic_law().
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

/// The names make_elastic_law() accepts: {"neo-hookean"}.
std::vector<std::string> elastic_law_names();

/// The law `name` with reference state (topology, reference positions) and modulus kS. Throws
/// bendlab::Error for an unknown name, kS <= 0 or a degenerate reference triangle.
std::unique_ptr<ElasticLaw> make_elastic_law(const std::string& name, TopologyPtr topology, const Points& reference,
                                             double kS);

}  // namespace bendlab
