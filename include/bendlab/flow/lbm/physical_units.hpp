#pragma once
// Physical units at the interface of a channel or tube run, lattice units inside
// (shared/spec/CELLS_IN_CHANNELS.md section 1; docs/conventions.md §6).
//
// The user gives the lattice spacing dx (um), the relaxation time tau, the plasma (viscosity eta,
// density rho), the geometry in um and the driving, either as the pseudo-shear rate v / D (tube)
// or v / H (slit channel) of the cell-free flow, v its mean velocity (Pries' measure, 1/s), or as
// the body force density g (N/m^3). The other follows from Poiseuille's law,
//   tube:    v = g D^2 / (32 eta),      u_max = 2 v
//   channel: v = g H^2 / (12 eta),      u_max = 3/2 v   (slit: plane walls at z = -+H/2),
// and the lattice units from
//   nu = eta / rho,  nu_lattice = (tau - 1/2) / 3,  dt = nu_lattice dx^2 / nu,
//   g_lattice = g dt^2 / (rho dx),  u_lattice = u dt / dx,
//   F_lattice = F dt^2 / (rho dx^4),  k_lattice = k dt^2 / (rho dx^3) (N/m),  E_lattice = E dt^2 / (rho dx^5),
// Mach number Ma = sqrt(3) u_max,lattice, Reynolds number Re = v D / nu (or v H / nu).
//
// The shear box (geometry shear): plane walls at z = -+H/2 moving with -+v e_x, periodic in x
// over the length and in y over the width, driven by the shear rate gamma = 2 v / H (1/s) alone:
// the linear shear flow u = gamma z e_x of the cell-free fluid, the box of `bendlab shear
// --solver lbm` in physical units. Its lattice has no solid layers (nz = H / dx, the walls
// halfway beyond the outermost nodes) and the collision of the shear command (Collision::Auto:
// BGK at tau = 1; a linear flow puts a bounce-back wall exactly halfway at any tau). There
// u_max = v, Ma = sqrt(3) v_lattice and Re = v (H / 2) / nu = gamma H^2 / (4 nu).
#include <optional>
#include <string>
#include <vector>

#include "bendlab/flow/lbm/lattice.hpp"

namespace bendlab::lbm {

enum class FlowGeometry { Tube, Channel, Shear };

/// "tube", "channel", "shear".
std::string to_string(FlowGeometry geometry);

/// Blood plasma at 37 C (docs/conventions.md §6: eta = 1.2 mPa s, rho = 1025 kg/m^3).
struct Plasma {
  double viscosity = 1.2e-3;  ///< eta, Pa s
  double density = 1025.0;    ///< rho, kg/m^3
};

struct FlowUnitsInput {
  FlowGeometry geometry = FlowGeometry::Tube;
  double diameter_um = 0;  ///< tube
  double height_um = 0;    ///< channel, shear: wall distance (z)
  double width_um = 0;     ///< channel, shear: periodic extent across the flow (y)
  double length_um = 0;    ///< periodic extent along the flow (x)
  double dx_um = 0.5;
  double tau = 1.0;
  Plasma plasma;
  std::optional<double> pseudo_shear_rate;  ///< v / D or v / H, 1/s
  std::optional<double> body_force;         ///< g, N/m^3
  std::optional<double> shear_rate;         ///< shear: gamma = 2 v / H, 1/s (the only driving)
  double max_mach = 0.1;                    ///< refused above this
  /// Time scaling S >= 1: the lattice works with the density S rho. In Stokes flow the density
  /// only sets the Reynolds number, so the physics stays the same while dt = nu_lattice dx^2 S rho
  /// / eta grows S-fold (a run needs S times fewer steps); Re grows S-fold too and is refused
  /// above kMaxScaledReynolds (docs/conventions.md §6, "Time scaling").
  double time_scale = 1.0;
  /// The density the lattice works with: plasma.density * time_scale.
  double lattice_density() const { return plasma.density * time_scale; }
};

/// The largest Reynolds number a time-scaled run (time_scale > 1) may reach: the D = 10 um tube's
/// eta_app, H_D and cell-free layer stayed within 2 standard errors of the unscaled run up to
/// S = 100, Re = 0.854, the largest S its Mach bound allows (docs/results/time_scaling.md); the
/// bound is that Re rounded down.
inline constexpr double kMaxScaledReynolds = 0.85;

struct FlowUnits {
  FlowUnitsInput input;
  int nx = 0, ny = 0, nz = 0;     ///< lattice nodes (two solid layers beyond every wall)
  double dt = 0;                  ///< s per step
  double nu = 0, nu_lattice = 0;  ///< m^2/s, dx^2/dt
  double body_force = 0;          ///< g, N/m^3
  double body_force_lattice = 0;
  double pseudo_shear_rate = 0;   ///< 1/s (shear: the walls' shear rate gamma)
  double mean_velocity = 0;       ///< v of the cell-free flow, m/s (shear: 0)
  double wall_velocity = 0;       ///< shear: v of the top wall, m/s (0 otherwise)
  double max_velocity_lattice = 0;
  double mach = 0, reynolds = 0;
  /// The section's size in dx: D / dx (tube) or H / dx (channel, shear).
  double section_lattice = 0;

  double dx() const { return input.dx_um * 1e-6; }
  /// Seconds of `steps` lattice steps.
  double seconds(double steps) const { return steps * dt; }
  /// The most lattice steps a run counts: beyond 2^53 a step count is no longer exact as a double
  /// (nor the run's time n dt), and far beyond it the 64-bit counters wrap.
  static constexpr double kMaxSteps = 9007199254740992.0;
  /// The lattice steps (rounded up, as a run steps to its end) to reach `seconds`, given by the
  /// option `option`. Throws bendlab::Error naming the option, dt and what sets it where that is
  /// less than one step (unless `below_one_step_ok`: a report interval shorter than a step reports
  /// every step) or more than kMaxSteps.
  double checked_steps(double seconds, const std::string& option, bool below_one_step_ok = false) const;
  /// Lattice velocity of a physical one (m/s) and back.
  double to_lattice_velocity(double u) const { return u * dt / dx(); }
  double to_physical_velocity(double u_lattice) const { return u_lattice * dx() / dt; }
  /// Lattice values of a force (N), a surface modulus or tension (N/m) and an energy (J): the
  /// lattice's mass unit is rho dx^3, its time unit dt.
  double to_lattice_force(double newtons) const;
  double to_lattice_modulus(double newtons_per_metre) const;
  double to_lattice_energy(double joules) const;
  /// The lines a run prints about the units it chose.
  std::vector<std::string> describe() const;
  /// The line describe() gives a time-scaled run: S, the lattice's density, Re and its bound.
  std::string time_scale_line() const;
};

/// Validates and converts. Throws bendlab::Error, naming the option, for: a non-positive or
/// non-finite size, dx, viscosity or density; tau <= 1/2; a channel height, width or length, or a
/// tube length, that is not a whole number of dx (within 1e-6 dx); a tube diameter below 4 dx;
/// neither or both drivings, or a negative one (shear: a shear rate, and no other driving); and a
/// Mach number above max_mach.
FlowUnits flow_units(const FlowUnitsInput& input);

/// The lattice of these units: TRT (walls exactly placed at any tau), the body force along x,
/// and the cross-section: the tube's (TubeWall of radius D / (2 dx), interpolated bounce-back) or
/// the channel's (SlabWall at z = -+H/2, halfway between nodes), periodic in x (and y); the shear
/// box's moving walls (LatticeConfig::walls, the collision of the shear command) without a body force.
LatticeConfig flow_lattice_config(const FlowUnits& units);

}  // namespace bendlab::lbm
