#pragma once
// Binary checkpoint of the lattice Boltzmann fluid: the raw populations (in the AA layout of the
// step's parity) and the step count, written atomically (core/atomic_file.hpp). The force field is
// not stored: ESPResSo's step order rebuilds it from the membrane at the start of every step.
//
// Format (little-endian as the machine writes it): 8-byte magic "BLLBMCK\0", uint32 version (1),
// uint32 Q (19), int32 nx, ny, nz, int32 walls (0/1), float64 tau, float64 wall velocity,
// int64 step, uint64 population count, then the populations as float64.
#include <filesystem>

#include "bendlab/flow/lbm/lattice.hpp"

namespace bendlab::lbm {

void write_checkpoint(const Lattice& lattice, const std::filesystem::path& path);

/// Restores populations and step into `lattice`, which must have the checkpoint's size, walls,
/// tau and wall velocity. Throws bendlab::Error naming the problem: missing file, wrong magic,
/// unknown version, mismatched lattice, wrong file size.
void read_checkpoint(Lattice& lattice, const std::filesystem::path& path);

}  // namespace bendlab::lbm
