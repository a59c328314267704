#pragma once
// Many cells in one lattice Boltzmann fluid (flow/lbm/lbm_suspension.hpp) over the ranks of an MPI
// communicator: the fluid in y-slabs (distributed_lattice.hpp), each cell owned whole by one rank
// (shared/spec/CELLS_IN_CHANNELS.md section 4; docs/mpi.md, "Many cells"). The run is the serial
// suspension's bit for bit, whatever the rank count.
//
// Ownership. The owner of a cell is the rank whose slab holds the layer of its centroid's y
// (recomputed from the positions at the start of every step, so a cell whose centroid crosses a
// slab face changes hands there); it alone computes the cell's forces and moves it. Every rank a
// cell can matter to holds a ghost copy of its positions for the step: the ranks whose layers the
// cell's immersed-boundary stencils reach, and those whose own cells can come within the contact
// cutoff of it (the layers within cutoff + E of the cell, E the largest distance in y of any cell's
// vertex from its centroid, agreed over the ranks once per step).
//
// One step, in LbmSuspension's order, with what crosses ranks:
//   a. the owners of the last step send each cell's positions to the ranks it reaches;
//   b. each owner computes its cells' membrane forces, the external force and the contact forces
//      (from the positions of the cells it holds; contact.hpp sums a vertex's pairs in row order,
//      so nearby cells give the serial forces) and the wall's;
//   c. the owners send the forces to the same ranks;
//   d. every rank spreads the forces of all cells it holds onto its own layers, cell after cell in
//      index order: each lattice node sums the serial terms in the serial order;
//   e. the fluid steps (DistributedLattice);
//   f. every rank computes the fluid velocity at the stencil nodes in its own layers and sends the
//      owner of each cell the values its vertices need; the owner sums each vertex's stencil in the
//      serial order;
//   g. the owner moves its cells (explicit Euler) and wraps them by a period as LbmSuspension does.
// Communication per step: three exchanges of positions, forces and stencil velocities with the
// ranks the cells reach (MPI_Alltoallv, empty for the others), and one reduction of two numbers (E
// and whether any rank failed). Nothing is reduced per cell.
//
// Errors (a membrane force that fails, a non-finite position, a stencil across a wall) are thrown
// on every rank alike, with the message of the lowest rank that met one.
// Threads: each rank's cells' membrane forces run a cell per OpenMP thread, as in LbmSuspension.
#include <mpi.h>

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "bendlab/flow/lbm/immersed_boundary.hpp"
#include "bendlab/flow/lbm/lbm_suspension.hpp"
#include "bendlab/membrane/membrane_model.hpp"
#include "bendlab/parallel/distributed_lattice.hpp"
#include "bendlab/suspension/contact.hpp"

namespace bendlab::parallel {

class MpiSuspension {
 public:
  /// As LbmSuspension's constructor (the same errors), with the fluid in y-slabs over `comm`.
  MpiSuspension(lbm::SuspensionOptions options, MPI_Comm comm);

  /// Adds a cell at positions X (lattice units); every rank adds the same cells in the same order.
  /// Returns its index. Throws as LbmSuspension::add_cell.
  int add_cell(std::shared_ptr<const MembraneModel> membrane, const Points& X);

  /// One step (a-g above; collective).
  void step();
  void run(std::int64_t steps) {
    for (std::int64_t s = 0; s < steps; ++s) step();
  }

  /// Every vertex, cell after cell, as LbmSuspension::positions() (collective: each owner's
  /// cells gathered onto every rank).
  Points gather_positions() const { return gather_rows(X_); }
  /// The vertex velocities of the last step, as LbmSuspension::velocities() (collective).
  Points gather_velocities() const { return gather_rows(U_); }
  /// Replaces every vertex by X (lattice units, the rows of gather_positions(); the same on every
  /// rank); the fluid is restored through fluid(). Throws bendlab::Error for a size mismatch.
  void restore(const Points& X);

  int num_cells() const { return static_cast<int>(cells_.size()); }
  Eigen::Index first_row(int c) const { return cells_[c].first; }
  Eigen::Index rows(int c) const { return cells_[c].membrane->num_vertices(); }
  const MembraneModel& membrane(int c) const { return *cells_[c].membrane; }
  /// The rank that owns cell c in this step (-1: this rank does not hold it).
  int owner(int c) const { return owner_[c]; }
  /// The cells this rank holds, owned or as ghosts, ascending.
  const std::vector<int>& held_cells() const { return held_; }
  DistributedLattice& fluid() { return fluid_; }
  const DistributedLattice& fluid() const { return fluid_; }
  const lbm::SuspensionOptions& options() const { return options_; }
  std::int64_t steps() const { return fluid_.step_count(); }

 private:
  struct Cell {
    std::shared_ptr<const MembraneModel> membrane;
    Eigen::Index first = 0;
  };
  // The ranks that need cell c's positions and forces in this step (ascending, this rank included
  // if it is one of them).
  std::vector<int> reach(int c) const;
  double centroid_y(int c) const;
  // The rows of M of every cell, from its owner, on every rank (collective).
  Points gather_rows(const Points& M) const;
  int owner_of_layer_at(double y) const;
  // The largest |y - centroid y| over the vertices of the cells in `cells`.
  double extent_y(const std::vector<int>& cells) const;
  // Sends the rows of M of each cell in `cells` (owned here) to the other ranks of its reach(),
  // and writes those the others send into M; returns the cells received, ascending.
  std::vector<int> exchange_rows(const std::vector<int>& cells, Points& M);
  // The first failure of this step on this rank.
  void fail(const std::string& what);
  // E for the next step, and whether any rank failed in this one: throws on every rank with the
  // message of the lowest failing rank (collective).
  void agree();
  void compute_forces(std::int64_t n);
  void spread_and_step(std::int64_t n);
  void compute_stencil_velocities();
  void interpolate_and_move(std::int64_t n);
  void wrap(int c);
  // The stencil of global row k (a row of a held cell) as entries from `at` on: each entry's
  // weight, the rank that owns its node's layer and, where that is this rank, its local node.
  // A stencil that cannot be made leaves zero weights and returns the reason.
  std::string make_stencil(Eigen::Index k, std::size_t at);

  lbm::SuspensionOptions options_;
  DistributedLattice fluid_;
  std::vector<Cell> cells_;
  std::vector<int> cell_of_;
  Points X_, F_, U_;  // global rows: X valid for the held cells, F for the held, U for the owned
  std::vector<int> owner_;
  std::vector<int> held_, owned_;
  double extent_y_ = 0;  // E, agreed over the ranks
  // Scratch.
  struct Scratch {
    Points x, f;
  };
  std::vector<Scratch> scratch_;
  ContactSearch contact_;
  Points held_x_, held_f_;
  std::vector<int> held_cell_of_;
  // The stencils of the held cells' rows, in held order, per_row_ entries each (zero weights
  // kept): 20 bytes an entry, where an lbm::IbStencil is 1 kB a row whatever the kernel.
  int per_row_ = 0;
  std::vector<Eigen::Index> held_rows_;      // the global row of each held row, in held order
  std::vector<double> entry_weight_;
  std::vector<int> entry_owner_;             // the rank owning the entry node's layer
  std::vector<std::size_t> entry_local_;     // its local node where that rank is this one
  std::vector<std::uint64_t> marks_;      // a bit per local node: in some stencil
  std::vector<std::size_t> touched_;      // the marked local nodes, ascending
  std::vector<double> node_velocity_;     // 3 per local node (those touched are current)
  std::string failure_;
};

}  // namespace bendlab::parallel
