#include "bendlab/flow/lbm/lbm_suspension.hpp"

#include <fmt/format.h>

#include <cmath>
#include <string>

#include <omp.h>

#include "bendlab/geometry/measures.hpp"

namespace bendlab::lbm {

SuspensionOptions checked_suspension_options(SuspensionOptions o) {
  o.cell_contact.validate();
  o.wall_contact.validate();
  if (!o.vertex_force.allFinite()) throw Error("suspension: the force per vertex is not finite");
  if (o.membrane_every < 1) throw Error(fmt::format("suspension: membrane forces every {} steps: must be at least 1", o.membrane_every));
  const LatticeConfig& c = o.lattice;
  if (std::abs(o.vessel.length() - c.nx) > 1e-9 || (o.vessel.periodic(1) && std::abs(o.vessel.width() - c.ny) > 1e-9)) {
    throw Error(fmt::format("suspension: the {} does not match the lattice's periods ({} x {} nodes)", o.vessel.describe(), c.nx, c.ny));
  }
  return o;
}

LbmSuspension::LbmSuspension(SuspensionOptions options) : options_(checked_suspension_options(std::move(options))), lattice_(options_.lattice) {}

void append_cell_rows(const MembraneModel* membrane, const Points& X, Points& all) {
  if (!membrane) throw Error("suspension: no membrane model for the cell");
  if (X.rows() != membrane->num_vertices() || X.cols() != 3) {
    throw Error(fmt::format("suspension: {} positions for a membrane of {} vertices", X.rows(), membrane->num_vertices()));
  }
  if (!X.allFinite()) throw Error("suspension: a cell position is not finite");
  Points grown(all.rows() + X.rows(), 3);
  grown.topRows(all.rows()) = all;
  grown.bottomRows(X.rows()) = X;
  all = std::move(grown);
}

int LbmSuspension::add_cell(std::shared_ptr<const MembraneModel> membrane, const Points& X) {
  const int c = num_cells();
  const Eigen::Index first = X_.rows();
  append_cell_rows(membrane.get(), X, X_);
  cells_.push_back(Cell{std::move(membrane), first});
  cell_of_.resize(X_.rows(), c);
  F_.setZero(X_.rows(), 3);
  U_.setZero(X_.rows(), 3);
  held_step_ = -1;
  return c;
}

void LbmSuspension::restore(Lattice lattice, const Points& X) {
  const LatticeConfig& a = lattice.config();
  const LatticeConfig& b = lattice_.config();
  if (a.nx != b.nx || a.ny != b.ny || a.nz != b.nz) throw Error("suspension: the restored lattice has another size");
  if (X.rows() != X_.rows() || !X.allFinite())
    throw Error(fmt::format("suspension: {} restored positions for {} vertices", X.rows(), X_.rows()));
  lattice_ = std::move(lattice);
  X_ = X;
  held_step_ = -1;
}

void LbmSuspension::step() {
  const std::int64_t n = lattice_.step_count() + 1;
  try {
    // 1. Forces at X(t), a cell per thread (a membrane model is safe to share between threads);
    // the first error is rethrown after the loop. With membrane_every N > 1 the membrane forces
    // are computed at the steps n - 1 = 0 mod N (or first after add_cell and restore) and held.
    const int every = options_.membrane_every;
    const bool hold = every > 1;
    const bool fresh = !hold || held_step_ < 0 || (n - 1) % every == 0;
    Points& membrane_forces = hold ? held_membrane_ : F_;
    if (hold) membrane_forces.resize(X_.rows(), 3);
    const int threads = fresh && cells_.size() > 1 ? omp_get_max_threads() : 1;
    if (static_cast<int>(scratch_.size()) < threads) scratch_.resize(static_cast<std::size_t>(threads));
    const auto cells = fresh ? static_cast<std::ptrdiff_t>(cells_.size()) : 0;
    std::string failure;
#pragma omp parallel for schedule(dynamic) num_threads(threads) if (threads > 1)
    for (std::ptrdiff_t c = 0; c < cells; ++c) {
      const Cell& cell = cells_[static_cast<std::size_t>(c)];
      Scratch& s = scratch_[static_cast<std::size_t>(omp_get_thread_num())];
      try {
        const Eigen::Index rows = cell.membrane->num_vertices();
        s.x = X_.middleRows(cell.first, rows);
        cell.membrane->forces(s.x, s.f);
        membrane_forces.middleRows(cell.first, rows) = s.f;
      } catch (const Error& e) {
#pragma omp critical
        if (failure.empty()) failure = fmt::format("cell {}: {}", c, e.what());
      }
    }
    if (!failure.empty()) throw Error(failure);
    if (hold) {
      if (fresh) held_step_ = n - 1;
      F_ = held_membrane_;
    }
    if (options_.vertex_force != Vec3::Zero()) F_.rowwise() += options_.vertex_force.transpose();
    cell_contact_energy_ = wall_contact_energy_ = 0;
    if (options_.cell_contact.max_force > 0 && cells_.size() > 1) {
      cell_contact_energy_ = contact_.add_cell_contact(options_.vessel, options_.cell_contact, X_, cell_of_, F_);
    }
    // A box's walls exist only where the lattice has them (the shear box's moving walls).
    const bool walls = options_.vessel.kind() != VesselKind::Box || lattice_.config().walls;
    if (options_.wall_contact.max_force > 0 && walls) {
      wall_contact_energy_ = add_wall_contact(options_.vessel, options_.wall_contact, X_, F_);
    }
    // 2-4, with the node velocities shared between overlapping stencils.
    lattice_.clear_force();
    interpolator_.prepare(lattice_, X_, options_.kernel);  // X's stencils, for 2 and 4
    interpolator_.spread(lattice_, F_);
    interpolator_.step_and_interpolate(lattice_, U_);  // the step, then U at X(t)
    euler_move(X_, U_, 1.0);
  } catch (const Error& e) {
    throw Error(fmt::format("suspension step {}: {}", n, e.what()));
  }
  for (Eigen::Index k = 0; k < X_.rows(); ++k) {
    if (!std::isfinite(X_(k, 0)) || !std::isfinite(X_(k, 1)) || !std::isfinite(X_(k, 2))) {
      const int c = cell_of_[k];
      throw Error(fmt::format("suspension blew up at step {}: vertex {} of cell {} has a non-finite position", n,
                              k - cells_[c].first, c));
    }
  }
  wrap_cells();
}

void LbmSuspension::wrap_cells() {
  const Vec3 period = options_.vessel.period();
  for (const Cell& cell : cells_) {
    const Eigen::Index rows = cell.membrane->num_vertices();
    const Vec3 centre = X_.middleRows(cell.first, rows).colwise().mean().transpose();
    for (int a = 0; a < 2; ++a) {
      if (!options_.vessel.periodic(a)) continue;
      const double shift = period[a] * std::floor(centre[a] / period[a] + 0.5);  // into [-P/2, P/2)
      if (shift != 0) X_.middleRows(cell.first, rows).col(a).array() -= shift;
    }
  }
}

}  // namespace bendlab::lbm
