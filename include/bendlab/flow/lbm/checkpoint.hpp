#pragma once
// Binary checkpoint of the lattice Boltzmann fluid: the raw populations (in the AA layout of the
// step's parity) and the step count, written atomically (core/atomic_file.hpp). The force field is
// not stored: ESPResSo's step order rebuilds it from the membrane at the start of every step.
//
// Format (little-endian as the machine writes it): 8-byte magic "BLLBMCK\0", uint32 version (1),
// uint32 Q (19), int32 nx, ny, nz, int32 walls (0/1), float64 tau, float64 wall velocity,
// int64 step, uint64 population count, then the populations as float64.
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>

#include "bendlab/flow/lbm/lattice.hpp"

namespace bendlab::lbm {

/// Bytes before the populations. Population q of global node i + nx (j + ny k) is the double at
/// kCheckpointHeaderBytes + 8 (q nx ny nz + i + nx (j + ny k)), whatever wrote the file: a
/// parallel run writes and reads its own part of the same layout (parallel/distributed_checkpoint.hpp).
inline constexpr std::size_t kCheckpointHeaderBytes = 8 + 4 + 4 + 4 * 4 + 8 + 8 + 8 + 8;
/// The header of a checkpoint of lattice `config` at `step`.
std::string checkpoint_header(const LatticeConfig& config, std::int64_t step);
/// Validates the header and size of the checkpoint at `path` against `config` (the same errors as
/// read_checkpoint) and returns its step count.
std::int64_t check_checkpoint_header(const LatticeConfig& config, const std::filesystem::path& path);

void write_checkpoint(const Lattice& lattice, const std::filesystem::path& path);

/// Restores populations and step into `lattice`, which must have the checkpoint's size, walls,
/// tau and wall velocity. Throws bendlab::Error naming the problem: missing file, wrong magic,
/// unknown version, mismatched lattice, wrong file size.
void read_checkpoint(Lattice& lattice, const std::filesystem::path& path);

}  // namespace bendlab::lbm
