#include "bendlab/parallel/slab_decomposition.hpp"

#include <fmt/format.h>

#include <algorithm>

namespace bendlab::parallel {

const int kLowerFaceSlots[kFacePopulations] = {4, 8, 9, 16, 18};
const int kUpperFaceSlots[kFacePopulations] = {3, 7, 10, 15, 17};

SlabDecomposition SlabDecomposition::of(int ny, int ranks, int rank) {
  if (ranks < 1 || rank < 0 || rank >= ranks) throw Error(fmt::format("rank {} of {} ranks is out of range", rank, ranks));
  if (ny < ranks)
    throw Error(fmt::format("{} ranks for a lattice of {} y-layers: every rank needs at least one layer (use at most {} ranks)",
                            ranks, ny, ny));
  SlabDecomposition s;
  s.ny = ny;
  s.ranks = ranks;
  s.rank = rank;
  const int base = ny / ranks, extra = ny % ranks;
  s.count = base + (rank < extra ? 1 : 0);
  s.begin = rank * base + std::min(rank, extra);
  return s;
}

int SlabDecomposition::owner(int j) const {
  const int base = ny / ranks, extra = ny % ranks;
  const int big = extra * (base + 1);  // layers of the larger slabs
  return j < big ? j / (base + 1) : extra + (j - big) / base;
}

std::size_t halo_bytes_per_step(const lbm::LatticeConfig& g) {
  return 2 * kFacePopulations * static_cast<std::size_t>(g.nx) * static_cast<std::size_t>(g.nz) * sizeof(double);
}

}  // namespace bendlab::parallel
