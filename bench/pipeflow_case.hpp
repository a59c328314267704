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

// A tube of diameter D and length L (um) at dx = 0.5 um and relaxation time tau, driven at a
// pseudo-shear rate of 100 1/s, with the lattice density `time_scale` times the plasma's.
inline FlowUnits tube_units(double diameter_um, double length_um, double tau, double time_scale = 1.0) {
  FlowUnitsInput in;
  in.geometry = FlowGeometry::Tube;
  in.diameter_um = diameter_um;
  in.length_um = length_um;
  in.dx_um = 0.5;
  in.tau = tau;
  in.pseudo_shear_rate = 100;
  in.time_scale = time_scale;
  return flow_units(in);
}

inline FlowUnits pipeflow_units() { return tube_units(25, 50, 1.0); }

// The suspension options of a tube: contact with the force `contact_newton` at contact and a
// cutoff of one dx, between cells and at the wall.
inline SuspensionOptions tube_options(const FlowUnits& u, double contact_newton) {
  SuspensionOptions o;
  o.lattice = flow_lattice_config(u);
  o.vessel = Vessel::tube(u.section_lattice, u.nx);
  const double cutoff = 1.0;
  o.cell_contact = ContactLaw{u.to_lattice_force(contact_newton), cutoff};
  o.wall_contact = ContactLaw{u.to_lattice_force(contact_newton), cutoff};
  return o;
}

inline SuspensionOptions pipeflow_options() { return tube_options(pipeflow_units(), 1e-12); }

// The tube study's reference case (scripts/tube_study.py, docs/results/tube_flow.md) as
// `bendlab flow` runs it at time scale 10: D = 10 um, 20 um periodic, tau = 1.82, red blood cells
// (mt1:1280, Method C, Skalak) at tube hematocrit 0.3 placed from seed 1 with flow's clearance
// (half the cutoff) and contact force (G_s dx): 40 x 24 x 24 nodes and 5 cells.
inline FlowUnits tube10_units() { return tube_units(10, 20, 1.82, 10.0); }

inline SuspensionOptions tube10_options() {
  const CellKindSpec rbc;
  return tube_options(tube10_units(), rbc.shear_modulus * 0.5e-6);
}

template <class S>
void add_tube10_cells(S& s) {
  const FlowUnits u = tube10_units();
  const CellKind rbc = make_cell_kind(CellKindSpec{});
  PlacementOptions p;
  p.hematocrit = 0.3;
  p.clearance = 0.25;
  p.seed = 1;
  const Placement reds = place_cells(Vessel::tube(10, 20), rbc.reference_um.topology(), rbc.reference_um.positions(), p);
  const auto membrane = lattice_membrane(rbc, u);
  for (const PlacedCell& c : reds.cells) s.add_cell(membrane, placed_positions(rbc.reference_um.positions(), c) / u.input.dx_um);
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
