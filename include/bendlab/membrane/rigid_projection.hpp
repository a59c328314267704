#pragma once
// The part of a nodal force field that moves a membrane as a rigid body, and its removal.
//
// A membrane's internal forces must have no net force and no net torque: the continuous bending
// force of a closed surface is the variation of an energy that translations and rotations leave
// unchanged. A discrete force that is the exact gradient of such an energy (Methods A, B, J) has
// none; one that evaluates the continuous force density at the vertices (C, D, E, M) can have
// both, from discretisation errors that do not cancel (docs/results/tube_flow.md measures them in
// a suspension). In a fluid, that net force pushes the cell through it with a force the physics
// does not have.
//
// remove_rigid_motion is the L2-orthogonal projection of F off the six rigid motions of the
// vertices x (translations, and infinitesimal rotations about the vertex centroid c):
//   F_i <- F_i - F_net / N - omega x (x_i - c),   I omega = T,
// with F_net = sum_i F_i, T = sum_i (x_i - c) x F_i and I = sum_i (|r_i|^2 1 - r_i r_i^T),
// r_i = x_i - c (positive definite unless the vertices are collinear). Afterwards the net force
// and the net torque vanish to round-off; a field without them is unchanged to round-off.
#include "bendlab/core/types.hpp"

namespace bendlab {

struct RigidParts {
  Vec3 force = Vec3::Zero();   ///< sum_i F_i
  Vec3 torque = Vec3::Zero();  ///< sum_i (x_i - c) x F_i about the vertex centroid c
};

/// The net force and the net torque about the vertex centroid of F on the vertices x.
RigidParts rigid_parts(const Points& x, const Points& F);

/// Removes the rigid-motion part of F (above). Throws bendlab::Error for sizes that differ or
/// vertices on one line (no rotation is determined about it).
void remove_rigid_motion(const Points& x, Points& F);

}  // namespace bendlab
