#pragma once
// A kind of cell in physical units (um, N/m, J), with the literature's defaults for a human red
// blood cell (shared/spec/CELLS_IN_CHANNELS.md section 2; docs/conventions.md §6 cites each):
//   shape      the red blood cell of the paper's eq. (15) with R = 3.91 um (diameter 7.82 um)
//   mesh       mt1:1280 (1280 triangles, 642 vertices; edges about 0.45 um)
//   membrane   Skalak law, G_s = 5.3 uN/m, C = 10; bending modulus 2e-19 J; Method C
//   volume     ESPResSo's volume force (membrane/espresso_volume_force.hpp) with
//              kappa_V = 100 kappa_S / R, R the cell's radius: the capsule runs' kappa_V = 100 kS
//              in their units of R (a force of kappa_V A_t grows with the square of the length
//              unit, so a ratio to kS needs one; R keeps it the same at every dx)
// Every cell of a kind shares its topology, reference shape and bending method: per cell a run
// keeps positions and forces only.
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "bendlab/bending/bending_method.hpp"
#include "bendlab/flow/lbm/physical_units.hpp"
#include "bendlab/membrane/membrane_model.hpp"
#include "bendlab/mesh/trimesh.hpp"

namespace bendlab {

struct CellKindSpec {
  std::string shape = "rbc";          ///< rbc (eq. (15)) or sphere
  double radius_um = 3.91;            ///< rbc: R of eq. (15), the large half-axis; sphere: its radius
  std::string mesh = "mt1:1280";      ///< a mesh_from_spec() name
  std::string elastic_law = "skalak"; ///< skalak or neo-hookean
  double shear_modulus = 5.3e-6;      ///< G_s, N/m (k_S = 3 G_s, docs/conventions.md §2)
  double skalak_c = 10;               ///< the Skalak law's C (area modulus G_s (1 + 2 C))
  double bending_modulus = 2e-19;     ///< kappa_B, J
  std::string method = "C";           ///< bending method ("none": no bending force)
  std::vector<std::string> method_options;  ///< name=value
  double volume_modulus_ratio = 100;  ///< kappa_V R / kappa_S of ESPResSo's volume force (R the radius)
  /// Removes the bending force's net force and torque on each cell (membrane/rigid_projection.hpp).
  bool bending_without_net_force = false;

  /// Sets bending_without_net_force from the choice of bendlab flow's --bending-net-force (Python's
  /// bending_net_force): "keep", "remove", or none for the flow runs' default, remove where there is
  /// a bending force (a method other than none and bending_modulus > 0; docs/conventions.md §6).
  /// Throws bendlab::Error naming the option for another value. Call it after method and
  /// bending_modulus are set.
  void choose_bending_net_force(const std::optional<std::string>& choice);
  /// Whether there is a bending force: a method other than none and bending_modulus > 0.
  bool has_bending() const { return method != "none" && bending_modulus > 0; }

  /// The fields that make a cell kind (a run's arguments): cell, cell_radius_um, mesh,
  /// elastic_law, shear_modulus, skalak_c, bending_modulus, method, method_options,
  /// volume_modulus_ratio, and bending_without_net_force where it is set (so that the runs made
  /// before the option keep their identity).
  nlohmann::json to_json() const;
};

/// Throws bendlab::Error, naming the option, for an unknown shape or law, a non-positive or
/// non-finite radius or modulus, a negative bending modulus, C <= -1/2, an unknown bending method
/// or options it refuses.
void check_cell_kind(const CellKindSpec& spec);

struct CellKind {
  CellKindSpec spec;
  TriMesh reference_um;   ///< the stress-free shape in um, volume centroid at the origin, axis e_z
  double volume_um3 = 0;  ///< of the mesh
  double area_um2 = 0;
  double mean_edge_um = 0;
};

CellKind make_cell_kind(const CellKindSpec& spec);

/// A warning (one line, with the ratio) when the kind's mean edge is longer than `max_ratio` times
/// dx: the immersed boundary then lets fluid leak through the membrane between the vertices
/// (shared/spec/LBM_IBM.md section 3: edges of at most 1-1.5 dx). Nothing otherwise.
std::optional<std::string> mesh_leak_warning(const CellKind& kind, double dx_um, double max_ratio = 1.5);

/// The membrane of a kind in lattice units (positions in dx, moduli by FlowUnits), sharing the
/// kind's topology and one bending method.
std::shared_ptr<const MembraneModel> lattice_membrane(const CellKind& kind, const lbm::FlowUnits& units);

/// The same membrane in um and pN, for a cell outside a flow (bendlab stretch): positions in um,
/// k_S = 3 G_s in pN/um (1 uN/m = 1 pN/um), kappa_B in pN um (1e-18 J), nodal forces in pN, and
/// the volume force of a flow run, kappa_V = ratio k_S / R (the cell's radius; docs/conventions.md §6).
std::shared_ptr<const MembraneModel> physical_membrane(const CellKind& kind);

}  // namespace bendlab
