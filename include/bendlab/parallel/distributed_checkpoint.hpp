#pragma once
// Checkpoint of a DistributedLattice: the serial checkpoint's file (flow/lbm/checkpoint.hpp: the
// header and the global populations in the AA layout of the step's parity, x fastest), so a file
// written by any number of ranks is read by any other number, or by the serial solver, and the
// serial solver's files are read here.
//   write: every rank writes its owned layers (19 x nz runs of nx x count doubles) with MPI-IO
//          into "<path>.tmp" beside the target, rank 0 the header; after MPI_File_sync and the
//          collective close, rank 0 renames the file onto the target (atomic: the last checkpoint
//          stays whole if any rank fails);
//   read:  every rank checks the header (the serial reader's errors) and reads its own layers.
// Both are collective; a failure on any rank throws bendlab::Error on every rank.
#include <filesystem>

#include "bendlab/parallel/distributed_lattice.hpp"

namespace bendlab::parallel {

void write_checkpoint(const DistributedLattice& lattice, const std::filesystem::path& path);
void read_checkpoint(DistributedLattice& lattice, const std::filesystem::path& path);

}  // namespace bendlab::parallel
