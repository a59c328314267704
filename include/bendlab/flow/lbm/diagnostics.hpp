#pragma once
// Blow-up detection for the lattice Boltzmann fluid: an unstable run shows up first as a
// non-finite or non-positive density somewhere.
#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "bendlab/flow/lbm/lattice.hpp"

namespace bendlab::lbm {

struct BlowUp {
  std::size_t node = 0;
  std::array<int, 3> ijk{};
  std::int64_t step = 0;
  double density = 0;
  std::string message;  ///< one line: what, where, when
};

/// The first node (in index order) whose density is not finite or not positive, or nothing.
std::optional<BlowUp> find_blow_up(const Lattice& lattice);

/// Per line of nodes along x, index j + ny k: u_x summed over i = 0 .. nx - 1 in that order
/// (lattice units; 0 for a solid row). The flow rate and the velocity profiles of a suspension
/// run add these (flow/suspension_recorder.hpp).
std::vector<double> line_velocity_sums(const Lattice& lattice);

}  // namespace bendlab::lbm
