#pragma once
// Domain decomposition of the D3Q19 lattice (flow/lbm/lattice.hpp) over MPI ranks: slabs of whole
// y-layers (docs/mpi.md). Why y:
//   - z carries the moving walls (bounce-back at z = -+nz/2): a z-split would put the walls on the
//     first and last rank only and split the wall code; with every rank holding all of z, the
//     bounce-back stays local and unchanged;
//   - x is the fastest index, the vectorised row of the collision kernel, with its periodic wrap
//     handled at the row ends; an x-split would cut the rows;
//   - so y, periodic: rank r owns layers begin <= j < begin + count, contiguous in rank order,
//     and exchanges with ranks r - 1 and r + 1 (mod ranks) only.
// Halo traffic: a D3Q19 population crosses a y-face if c_y != 0, 5 of 19 per face and direction.
// With the AA pattern every step has exactly one exchange of these 5 populations per face: after
// an even (in-place) step the ghost layers are filled with the neighbours' outgoing populations;
// after an odd (streaming) step the populations written into the ghost layers are returned.
// So a rank sends 2 faces x 5 x nx nz doubles per step and receives as many.
#include <cstddef>
#include <cstdint>

#include "bendlab/flow/lbm/lattice.hpp"

namespace bendlab::parallel {

struct SlabDecomposition {
  int ny = 0, ranks = 1, rank = 0;
  int begin = 0, count = 0;  ///< the owned y-layers begin <= j < begin + count

  /// ny layers over `ranks`: the first ny % ranks ranks get one layer more. Throws bendlab::Error
  /// if a rank would own no layer (ranks > ny) or the arguments are out of range.
  static SlabDecomposition of(int ny, int ranks, int rank);
  /// The rank owning layer j (0 <= j < ny).
  int owner(int j) const;
  bool owns(int j) const { return j >= begin && j < begin + count; }
};

/// The y-populations that cross a face: slots with c_y = -1 (lower face) and c_y = +1 (upper face).
inline constexpr int kFacePopulations = 5;
extern const int kLowerFaceSlots[kFacePopulations];
extern const int kUpperFaceSlots[kFacePopulations];

/// Bytes one rank sends per lattice step (and receives): 2 faces x 5 populations x nx nz doubles
/// (none with one rank, whose exchange is a copy into itself: counted all the same).
std::size_t halo_bytes_per_step(const lbm::LatticeConfig& global);

}  // namespace bendlab::parallel
