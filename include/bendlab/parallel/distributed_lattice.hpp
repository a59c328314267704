#pragma once
// The D3Q19 lattice Boltzmann fluid (flow/lbm/lattice.hpp) split over the ranks of an MPI
// communicator in y-slabs (slab_decomposition.hpp). Each rank keeps a local Lattice of
// nx x (count + 2) x nz nodes: its owned layers at local j = 1..count and one ghost layer on
// either side (local j = 0 and count + 1), and steps only the owned layers
// (Lattice::step_layers), so the collision and streaming code, the walls and the x wrap are the
// serial solver's. With the AA pattern:
//   even step (in place): no neighbour is read; afterwards the ghost layers receive the
//     neighbours' post-collision populations that stream into this slab (fill);
//   odd step (streaming): the owned nodes read the ghost layers and write the populations that
//     leave the slab into them; afterwards these go back to their owners (return), except the
//     slots that a wall's bounce-back writes on the owner itself.
// A cross-section (a tube's or channel's walls, section_walls.hpp) is the global one shifted to
// the local layers; its interpolated bounce-back runs after the exchange, since it reads
// populations that stream in from the ghost layers, and the return leaves alone the slots of solid
// rows and those whose source row is solid (the owner's bounce-back writes them).
// The owned nodes' slots then equal the serial lattice's at every step, so the fields are the
// serial solver's bit for bit, and the owned part of the raw store is the global AA layout
// (a checkpoint is the same file whatever the rank count: distributed_checkpoint.hpp).
// Every member that communicates is collective: all ranks call it in the same order.
#include <mpi.h>

#include <cstdint>
#include <functional>
#include <vector>

#include "bendlab/flow/lbm/lattice.hpp"
#include "bendlab/parallel/slab_decomposition.hpp"

namespace bendlab::parallel {

class DistributedLattice {
 public:
  /// `global` is the whole lattice (validated as Lattice does); throws bendlab::Error if the
  /// communicator has more ranks than y-layers. At rest, rho = 1, as Lattice.
  DistributedLattice(const lbm::LatticeConfig& global, MPI_Comm comm);

  const lbm::LatticeConfig& config() const { return global_; }
  MPI_Comm comm() const { return comm_; }
  const SlabDecomposition& slab() const { return slab_; }
  /// The local lattice: owned layers at local j = 1..count, ghosts at 0 and count + 1.
  lbm::Lattice& local() { return local_; }
  const lbm::Lattice& local() const { return local_; }
  std::int64_t step_count() const { return local_.step_count(); }
  double shear_rate() const { return local_.shear_rate(); }
  double viscosity() const { return local_.viscosity(); }
  /// The local node of global node (i, j, k), j owned or a ghost layer (begin - 1, begin + count).
  std::size_t local_node(int i, int j, int k) const { return local_.index(i, j - slab_.begin + 1, k); }
  /// Global position of global node (i, j, k).
  Vec3 position(int i, int j, int k) const;

  /// Lattice::initialise at the global node positions (owned layers; collective).
  void initialise(const std::function<Vec3(const Vec3&)>& velocity,
                  const std::function<double(const Vec3&)>& density = nullptr);
  /// Lattice::initialise_shear_flow (collective).
  void initialise_shear_flow();

  /// One step of the owned layers and the halo exchange of its parity (collective).
  void step();

  /// Replaces the owned part of the raw store by `owned` (kQ x nx x count x nz doubles,
  /// slot-major, x fastest: the global layout restricted to the owned layers) at `step`, and
  /// fills the ghost layers if the step count is odd (collective).
  void restore_owned(const std::vector<double>& owned, std::int64_t step);

  /// Doubles sent to the neighbours so far (halo traffic; bytes = 8 x this).
  std::int64_t halo_doubles_sent() const { return halo_doubles_; }
  /// Wall seconds spent in the halo exchange so far (packing, MPI, unpacking; for benchmarks).
  double halo_seconds() const { return halo_seconds_; }

  /// Throws bendlab::Error on every rank, naming the node and step as lbm::find_blow_up does, if
  /// any owned node has a non-finite or non-positive density (collective).
  void check_blow_up() const;

  /// Sum over all ranks of rho and of sum f c (without F/2) over the owned fluid nodes (collective;
  /// the order of the sum differs from Lattice's).
  double total_mass() const;

 private:
  void exchange(bool fill);

  lbm::LatticeConfig global_;
  MPI_Comm comm_;
  SlabDecomposition slab_;
  lbm::Lattice local_;
  std::vector<double> send_lo_, send_hi_, recv_lo_, recv_hi_;
  std::int64_t halo_doubles_ = 0;
  double halo_seconds_ = 0;
};

}  // namespace bendlab::parallel
