#pragma once
// The membrane of a capsule as ONE force model (paper sections 2 and 4.2): in-plane elasticity
// (an ElasticLaw: neo-Hookean by default, eqs. (18)-(21), or Skalak) + bending (any BendingMethod, eq. (10)
// or an energy gradient) + an optional volume force, all relative to one reference state
// (reference positions + shared Topology). The capsule may start in another shape than its
// reference (initial_positions(); a red blood cell stress-free as a spheroid): the volume force
// keeps the initial shape's volume.
//
//   F = F_elastic + F_bending + F_volume   (nodal forces, N x 3)
//   f = F / A_mixed                         (force density, eq. (14); Meyer's mixed area of the
//                                            current shape)
//
// Flow solvers only ask for F or f; none knows how they are made. The model owns its parts
// (shared_ptr to immutable objects: a model can be copied cheaply and shared between solvers).
// Every method is const and allocates its scratch per call, so concurrent calls are safe.
// Units: kS and kB are given directly (see bendlab/capsule/shear_units.hpp for the shear run's
// dimensionless G and kappa_b_hat).
#include <memory>
#include <optional>
#include <string>

#include "bendlab/bending/bending_method.hpp"
#include "bendlab/core/types.hpp"
#include "bendlab/elasticity/elastic_law.hpp"
#include "bendlab/membrane/volume_force.hpp"
#include "bendlab/mesh/trimesh.hpp"

namespace bendlab {

struct MembraneParameters {
  double kS = 1;                  ///< in-plane modulus of the elastic law (> 0)
  double kB = 0;                  ///< bending modulus (>= 0; > 0 needs `bending`)
  std::string elastic_law = "neo-hookean";  ///< a name of make_elastic_law(): neo-hookean, skalak
  double skalak_c = kDefaultSkalakC;        ///< the Skalak law's C (> -1/2; elasticity/skalak.hpp)
  std::shared_ptr<const BendingMethod> bending;  ///< nullptr: no bending forces
  std::shared_ptr<const VolumeForce> volume_force;  ///< nullptr: none
  /// Spontaneous curvature and ADE of the bending energy (docs/conventions.md §5); its kappa_b is
  /// not used (kB above is). Plain (the default): the paper's bending force.
  BendingParameters bending_terms;
  /// Removes the bending force's net force and net torque on the membrane (rigid_projection.hpp):
  /// momentum-conserving bending for the methods whose discrete force has them (C, D, E, M).
  /// Off (the default): the method's force as it is.
  bool bending_without_net_force = false;
  /// The bending parameters the method receives: bending_terms with kappa_b = kB.
  BendingParameters bending_parameters() const {
    BendingParameters p = bending_terms;
    p.kappa_b = kB;
    return p;
  }
};

/// The nodal forces of one shape and what they are made of.
struct MembraneForces {
  Points force;          ///< F, N x 3
  Points density;        ///< f = F / A_mixed, N x 3 (eq. (14))
  Scalars mixed_area;    ///< A_mixed of the current shape, N
};

class MembraneModel {
 public:
  /// `reference` is the stress-free shape (its positions and topology are kept). Throws
  /// bendlab::Error for kS <= 0, kB < 0, non-finite moduli, kB > 0 without a bending method, an
  /// unknown elastic law or a degenerate reference triangle.
  MembraneModel(const TriMesh& reference, MembraneParameters parameters);
  /// A capsule that starts in another shape than its stress-free one (a red blood cell whose
  /// reference is a spheroid, docs/conventions.md §2): `initial` (N x 3) are the positions a
  /// solver starts from and the volume its volume correction keeps. Throws as above, and for
  /// initial positions of the wrong size, not finite or enclosing no positive volume.
  MembraneModel(const TriMesh& reference, MembraneParameters parameters, const Points& initial);

  /// F (resized to N x 3) for positions x. Throws NonFiniteError (core/finite_check.hpp) naming
  /// the stage (elastic law, bending method, volume force) and the first vertex where a position
  /// or a force is not finite; force_density() also checks F / A_mixed.
  void forces(const Points& x, Points& force) const;
  /// f = F / A_mixed (resized to N x 3) for positions x (eq. (14)).
  void force_density(const Points& x, Points& density) const;
  /// F, f and A_mixed in one pass.
  MembraneForces evaluate(const Points& x) const;

  /// E_S of the elastic law.
  double elastic_energy(const Points& x) const;
  /// E_B where the bending method derives from an energy (std::nullopt otherwise or without one).
  std::optional<double> bending_energy(const Points& x) const;
  /// The volume force's energy (std::nullopt without one or if it has none).
  std::optional<double> volume_energy(const Points& x) const;

  double kS() const { return parameters_.kS; }
  double kB() const { return parameters_.kB; }
  const MembraneParameters& parameters() const { return parameters_; }
  const BendingMethod* bending() const { return parameters_.bending.get(); }
  const ElasticLaw& elastic_law() const { return *elastic_; }
  const Topology& topology() const { return *topology_; }
  const TopologyPtr& topology_ptr() const { return topology_; }
  const Points& reference_positions() const { return reference_; }
  /// Enclosed volume of the reference shape.
  double reference_volume() const { return reference_volume_; }
  /// The positions a solver starts from: the reference positions unless given apart.
  const Points& initial_positions() const { return initial_; }
  /// Enclosed volume of the initial shape: the volume the solvers' volume correction (BIM's
  /// rescaling, the volume force) keeps; equal to reference_volume() unless the shapes differ.
  double initial_volume() const { return initial_volume_; }
  int num_vertices() const { return topology_->num_vertices(); }

 private:
  TopologyPtr topology_;
  Points reference_;
  MembraneParameters parameters_;
  std::shared_ptr<const ElasticLaw> elastic_;
  double reference_volume_ = 0;
  Points initial_;
  double initial_volume_ = 0;
};

}  // namespace bendlab
