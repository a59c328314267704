#include "bendlab/flow/lbm/diagnostics.hpp"

#include <fmt/format.h>

#include <cmath>
#include <limits>

namespace bendlab::lbm {

std::optional<BlowUp> find_blow_up(const Lattice& lattice) {
  const auto n = static_cast<std::int64_t>(lattice.num_nodes());
  std::int64_t first = std::numeric_limits<std::int64_t>::max();
#pragma omp parallel for schedule(static) reduction(min : first) if (n >= (1 << 15))
  for (std::int64_t node = 0; node < n; ++node) {
    const double rho = lattice.density(static_cast<std::size_t>(node));
    if (!std::isfinite(rho) || !(rho > 0)) first = std::min(first, node);
  }
  if (first == std::numeric_limits<std::int64_t>::max()) return std::nullopt;
  BlowUp b;
  b.node = static_cast<std::size_t>(first);
  b.ijk = lattice.coordinates(b.node);
  b.step = lattice.step_count();
  b.density = lattice.density(b.node);
  const Vec3 x = lattice.position(b.ijk[0], b.ijk[1], b.ijk[2]);
  b.message = fmt::format("LBM blew up at step {}: density {} at node ({}, {}, {}) (position {:.3g}, {:.3g}, {:.3g})",
                          b.step, b.density, b.ijk[0], b.ijk[1], b.ijk[2], x.x(), x.y(), x.z());
  return b;
}

std::vector<double> line_velocity_sums(const Lattice& lattice) {
  std::vector<double> lines(static_cast<std::size_t>(lattice.ny()) * lattice.nz(), 0.0);
  for (int k = 0; k < lattice.nz(); ++k)
    for (int j = 0; j < lattice.ny(); ++j) {
      if (lattice.solid_row(j, k)) continue;
      double line = 0;
      for (int i = 0; i < lattice.nx(); ++i) line += lattice.velocity(lattice.index(i, j, k)).x();
      lines[static_cast<std::size_t>(j) + static_cast<std::size_t>(lattice.ny()) * k] = line;
    }
  return lines;
}

}  // namespace bendlab::lbm
