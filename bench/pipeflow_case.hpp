#pragma once
// The case of HemoCell's pipeflow example (CELLS_IN_CHANNELS.md; issue "Many cells"): a tube 25 um
// across and 50 um long at dx = 0.5 um, tau = 1, 36 red blood cells of 1280 triangles (Method C)
// and 6 small stiff cells, for bench_suspension (one process) and bench_suspension_mpi (ranks).
#include <cmath>

#include "bendlab/flow/cell_kind.hpp"
#include "bendlab/flow/lbm/lbm_suspension.hpp"
#include "bendlab/flow/lbm/physical_units.hpp"
#include "bendlab/suspension/placement.hpp"

namespace bendlab::bench {

using namespace bendlab::lbm;

inline FlowUnits pipeflow_units() {
  FlowUnitsInput in;
  in.geometry = FlowGeometry::Tube;
  in.diameter_um = 25;
  in.length_um = 50;
  in.dx_um = 0.5;
  in.tau = 1.0;
  in.pseudo_shear_rate = 100;
  return flow_units(in);
}

inline SuspensionOptions pipeflow_options() {
  const FlowUnits u = pipeflow_units();
  SuspensionOptions o;
  o.lattice = flow_lattice_config(u);
  o.vessel = Vessel::tube(u.section_lattice, u.nx);
  const double cutoff = 1.0;
  o.cell_contact = ContactLaw{u.to_lattice_force(1e-12), cutoff};
  o.wall_contact = ContactLaw{u.to_lattice_force(1e-12), cutoff};
  return o;
}

// The cells of the case: 36 red blood cells (or the count of `hematocrit`, red cells only) and 6
// small stiff spheres where the red ones leave room. `S` is LbmSuspension or
// parallel::MpiSuspension (every rank adds the same cells); `positions()` gives all of its
// vertices so far.
template <class S, class AllPositions>
void add_pipeflow_cells(S& s, double hematocrit, AllPositions&& positions) {
  const FlowUnits u = pipeflow_units();
  const CellKind rbc = make_cell_kind(CellKindSpec{});
  CellKindSpec small;
  small.shape = "sphere";
  small.radius_um = 1.5;
  small.mesh = "mt1:320";
  small.shear_modulus = 10 * 5.3e-6;
  const CellKind stiff = make_cell_kind(small);
  const Vessel tube_um = Vessel::tube(25, 50);
  PlacementOptions p;
  if (hematocrit > 0) {
    p.hematocrit = hematocrit;
  } else {
    p.count = 36;
  }
  p.clearance = 0.25;
  p.seed = 1;
  const Placement reds = place_cells(tube_um, rbc.reference_um.topology(), rbc.reference_um.positions(), p);
  const auto red_membrane = lattice_membrane(rbc, u);
  const auto stiff_membrane = lattice_membrane(stiff, u);
  for (const PlacedCell& c : reds.cells) s.add_cell(red_membrane, placed_positions(rbc.reference_um.positions(), c) / u.input.dx_um);
  if (hematocrit > 0) return;
  // The small cells where the red ones leave room: placed among them by trying positions.
  int added = 0;
  for (int k = 0; k < 400 && added < 6; ++k) {
    PlacedCell c;
    c.centre = Vec3(-25.0 + 50.0 * ((k * 37) % 100) / 100.0, 9.0 * std::cos(k), 9.0 * std::sin(k));
    const Points x = placed_positions(stiff.reference_um.positions(), c) / u.input.dx_um;
    bool clear = true;
    const Points all = positions();
    for (Eigen::Index i = 0; i < x.rows() && clear; ++i) {
      for (Eigen::Index j = 0; j < all.rows() && clear; ++j) {
        Vec3 d = row(x, i) - row(all, j);
        d.x() -= u.nx * std::round(d.x() / u.nx);
        clear = d.norm() > 1.0;
      }
    }
    if (clear) {
      s.add_cell(stiff_membrane, x);
      ++added;
    }
  }
}

}  // namespace bendlab::bench
