#pragma once
// Many cells in one lattice Boltzmann fluid (shared/spec/CELLS_IN_CHANNELS.md; docs/design.md,
// "Channels, tubes and many cells"). Lattice units throughout (dx = dt = 1, rho0 = 1).
//
// A cell is a membrane model (shared by every cell of its kind: one topology, one bending method
// and its connectivity caches) and its own rows of one position array X (all cells' vertices,
// cell after cell): per cell the suspension keeps positions, forces and velocities only. One step,
// in ESPResSo's order as for the single capsule (immersed_boundary.hpp):
//   1. F = each cell's membrane forces at X(t), + the external force per vertex, + the contact
//      forces between vertices of different cells and with the vessel's wall (contact.hpp);
//   2. spread F onto the lattice; 3. collide (with the body force) and stream;
//   4. interpolate U at X and move X by U (explicit Euler);
//   5. a cell whose vertex mean left the box along a periodic axis moves back whole by one
//      period (its vertices stay together: positions are unwrapped, the stencils and the contact
//      search take the nearest image).
// Blow-up: a non-finite position throws bendlab::Error naming the step, cell and vertex.
// Threads: the cells' membrane forces (1) run a cell per OpenMP thread, the immersed boundary's
// stencils and velocities on the threads too (IbInterpolator); results do not depend on the count.
#include <cstdint>
#include <memory>
#include <vector>

#include "bendlab/flow/lbm/immersed_boundary.hpp"
#include "bendlab/flow/lbm/lattice.hpp"
#include "bendlab/membrane/membrane_model.hpp"
#include "bendlab/suspension/contact.hpp"
#include "bendlab/suspension/vessel.hpp"

namespace bendlab::lbm {

struct SuspensionOptions {
  LatticeConfig lattice;
  /// The vessel in lattice units, matching the lattice (its walls where the lattice's are).
  Vessel vessel = Vessel::box(1, 1, 1);
  IbKernel kernel = IbKernel::Phi2;
  ContactLaw cell_contact{0, 1};  ///< between vertices of different cells (max_force 0: none)
  ContactLaw wall_contact{0, 1};  ///< between a vertex and the wall
  Vec3 vertex_force = Vec3::Zero();  ///< an external force on every vertex (sedimentation, a push)
  /// The cells' membrane forces (elasticity, bending, volume) are computed at the steps whose
  /// count before the step is a multiple of this and held in between, as HemoCell's
  /// stepMaterialEvery; contact and external forces, the spreading and the move stay every step.
  /// 1: every step. One process only (the MPI suspension refuses more).
  int membrane_every = 1;
};

/// The options as LbmSuspension takes them; throws bendlab::Error for a bad lattice or contact
/// law, or a vessel whose periods differ from the lattice's (shared with the MPI suspension).
SuspensionOptions checked_suspension_options(SuspensionOptions options);
/// Appends a cell's positions X to the rows of `all`; throws bendlab::Error (leaving `all` as it
/// was) for a null model, a size mismatch or a non-finite position (shared with the MPI suspension).
void append_cell_rows(const MembraneModel* membrane, const Points& X, Points& all);

class LbmSuspension {
 public:
  /// Throws bendlab::Error for a bad lattice or contact law, or a vessel whose periods differ
  /// from the lattice's.
  explicit LbmSuspension(SuspensionOptions options);

  /// Adds a cell of the kind `membrane` at positions X (lattice units, N x 3 with N the model's
  /// vertices); returns its index. Throws for a null model, a size mismatch or a non-finite position.
  int add_cell(std::shared_ptr<const MembraneModel> membrane, const Points& X);

  /// One step (1-5 above).
  void step();
  void run(std::int64_t steps) {
    for (std::int64_t s = 0; s < steps; ++s) step();
  }

  /// Replaces the fluid and every vertex by a checkpoint's: `lattice` of this configuration, X of
  /// positions()' rows (lattice units). Throws bendlab::Error for a mismatch.
  void restore(Lattice lattice, const Points& X);

  int num_cells() const { return static_cast<int>(cells_.size()); }
  /// Rows of cell c in positions(): [first_row(c), first_row(c) + rows(c)).
  Eigen::Index first_row(int c) const { return cells_[c].first; }
  Eigen::Index rows(int c) const { return cells_[c].membrane->num_vertices(); }
  const MembraneModel& membrane(int c) const { return *cells_[c].membrane; }
  /// All vertices, cell after cell (lattice units, unwrapped).
  const Points& positions() const { return X_; }
  /// The positions of cell c (a copy).
  Points cell_positions(int c) const { return X_.middleRows(first_row(c), rows(c)); }
  /// The vertex velocities of the last step.
  const Points& velocities() const { return U_; }
  /// The vertex forces the last step spread (membrane, external and contact forces).
  const Points& forces() const { return F_; }
  /// The cell of each row of positions().
  const std::vector<int>& cell_of_row() const { return cell_of_; }
  const Lattice& lattice() const { return lattice_; }
  Lattice& lattice() { return lattice_; }
  const SuspensionOptions& options() const { return options_; }
  std::int64_t steps() const { return lattice_.step_count(); }
  /// Contact energies of the last step's forces (diagnostics).
  double cell_contact_energy() const { return cell_contact_energy_; }
  double wall_contact_energy() const { return wall_contact_energy_; }

 private:
  struct Cell {
    std::shared_ptr<const MembraneModel> membrane;
    Eigen::Index first = 0;
  };
  void wrap_cells();

  SuspensionOptions options_;
  Lattice lattice_;
  std::vector<Cell> cells_;
  std::vector<int> cell_of_;
  Points X_, F_, U_;
  // The held membrane forces (membrane_every > 1) and the step count at which they were computed
  // (-1: none, after add_cell and restore).
  Points held_membrane_;
  std::int64_t held_step_ = -1;
  struct Scratch {
    Points x, f;  // one cell's positions and forces
  };
  std::vector<Scratch> scratch_;  // per OpenMP thread
  ContactSearch contact_;
  IbInterpolator interpolator_;
  double cell_contact_energy_ = 0, wall_contact_energy_ = 0;
};

}  // namespace bendlab::lbm
