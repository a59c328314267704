#pragma once
// The shear stress the fluid of a shear box exerts on its moving walls (docs/conventions.md §6,
// "The shear box"), from the populations of the node layers next to the walls. Lattice units.
//
// In a lattice Boltzmann fluid whose stress moments relax with 1/tau (BGK, the regularised
// scheme, TRT's even part) the viscous stress of a node is
//   sigma_ab = -(1 - 1/(2 tau)) Pi^neq_ab,   Pi^neq = sum_i f_i c_i c_i - rho u u - rho/3 I,
// f the post-stream (pre-collision) populations and u the velocity with the forcing's F/2; in
// the linear shear flow u = gamma z e_x it is mu gamma. The x momentum carried towards -z through
// a plane is sigma_xz - rho u_x u_z; averaged over a plane it is the same on every plane where no
// force acts (a steady flow), so on the layers next to the walls, which no cell reaches, it is the
// stress on the walls. wall_shear_stress averages it over both layers; divided by mu gamma it is
// the suspension's effective viscosity relative to the plasma's, 1 for the cell-free flow.
#include "bendlab/flow/lbm/lattice.hpp"

namespace bendlab::lbm {

/// The mean of sigma_xz - rho u_x u_z over the node layers k = 0 and k = nz - 1 (lattice units).
/// Throws bendlab::Error for a lattice without walls at z = -+nz/2 (LatticeConfig::walls).
double wall_shear_stress(const Lattice& lattice);

}  // namespace bendlab::lbm
