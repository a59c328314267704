// The rigid-motion projection of a nodal force field (membrane/rigid_projection.hpp): it removes
// the net force and torque and nothing else (an orthogonal projection: idempotent, its removed
// part a rigid field), leaves an energy gradient's field as it is, and, as the membrane's option,
// makes Method C's bending force free of net force and torque on a deformed red blood cell.
#include <gtest/gtest.h>

#include <random>

#include "bendlab/bending/bending_method.hpp"
#include "bendlab/membrane/membrane_model.hpp"
#include "bendlab/membrane/rigid_projection.hpp"
#include "bendlab/mesh/generators.hpp"
#include "bendlab/surfaces/analytic_surface.hpp"
#include "membrane/deformations.hpp"

using namespace bendlab;

namespace {

Points random_points(int n, unsigned seed, double scale = 1.0) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> g(0.0, scale);
  Points x(n, 3);
  for (int i = 0; i < n; ++i) x.row(i) << g(rng) + 2.0, g(rng) - 1.0, g(rng) + 0.5;  // off the origin
  return x;
}

double dot(const Points& a, const Points& b) { return (a.array() * b.array()).sum(); }

}  // namespace

TEST(RigidProjection, RemovesNetForceAndTorqueAndNothingElse) {
  const Points x = random_points(60, 3);
  const Points F = random_points(60, 4, 2.0);
  const RigidParts before = rigid_parts(x, F);
  ASSERT_GT(before.force.norm(), 1.0);  // random forces have both
  ASSERT_GT(before.torque.norm(), 1.0);
  Points P = F;
  remove_rigid_motion(x, P);
  const RigidParts after = rigid_parts(x, P);
  const double scale = F.norm();
  EXPECT_LT(after.force.norm(), 1e-13 * scale);
  EXPECT_LT(after.torque.norm(), 1e-13 * scale * x.norm());
  // An orthogonal projection: the removed part is orthogonal to what stays, projecting twice
  // changes nothing, and the removed part is itself rigid (its projection is zero).
  const Points removed = F - P;
  EXPECT_LT(std::abs(dot(removed, P)), 1e-12 * scale * scale);
  Points twice = P;
  remove_rigid_motion(x, twice);
  EXPECT_LT((twice - P).cwiseAbs().maxCoeff(), 1e-13 * scale);
  Points rigid = removed;
  remove_rigid_motion(x, rigid);
  EXPECT_LT(rigid.cwiseAbs().maxCoeff(), 1e-13 * scale);
}

TEST(RigidProjection, LeavesAnEnergyGradientAlone) {
  // Springs between vertex pairs: E = sum (|x_i - x_j| - 1)^2 / 2 does not change under
  // translations and rotations, so its gradient has no net force or torque.
  const Points x = random_points(30, 7);
  Points F = Points::Zero(x.rows(), 3);
  for (int i = 0; i < x.rows(); ++i)
    for (int j = i + 1; j < x.rows(); j += 3) {
      const Vec3 d = row(x, i) - row(x, j);
      const Vec3 f = -(d.norm() - 1.0) * d / d.norm();
      F.row(i) += f.transpose();
      F.row(j) -= f.transpose();
    }
  Points P = F;
  remove_rigid_motion(x, P);
  EXPECT_LT((P - F).cwiseAbs().maxCoeff(), 1e-12 * F.cwiseAbs().maxCoeff());
}

TEST(RigidProjection, RefusesCollinearVerticesAndSizeMismatch) {
  Points x(4, 3);
  x << 0, 0, 0, 1, 1, 1, 2, 2, 2, 3, 3, 3;
  Points F = Points::Ones(4, 3);
  EXPECT_THROW(remove_rigid_motion(x, F), Error);
  Points G = Points::Ones(3, 3);
  EXPECT_THROW(remove_rigid_motion(random_points(4, 1), G), Error);
}

TEST(RigidProjection, MembraneOptionMakesMethodCsBendingForceFreeOfNetForceAndTorque) {
  const TriMesh s = sphere_mesh(MeshFamily::MT1, 3);
  const TriMesh m = s.with_positions(make_rbc(1.0)->map_from_unit_sphere(s.positions()));
  const Points x = test::deform(m.positions());
  MembraneParameters p;
  p.kS = 1e-6;  // the elastic force is an energy gradient: it adds no net force either way
  p.kB = 1.0;
  p.bending = make_bending_method("C");
  const MembraneModel plain(m, p);
  p.bending_without_net_force = true;
  const MembraneModel projected(m, p);
  Points f_plain, f_projected;
  plain.forces(x, f_plain);
  projected.forces(x, f_projected);
  const double scale = f_plain.norm();
  const RigidParts a = rigid_parts(x, f_plain), b = rigid_parts(x, f_projected);
  EXPECT_GT(a.force.norm(), 1e-6 * scale);  // Method C's force has a net force on this shape
  EXPECT_LT(b.force.norm(), 1e-12 * scale);
  EXPECT_LT(b.torque.norm(), 1e-12 * scale);
  // Only the rigid part changed: the difference is a rigid field.
  Points diff = f_plain - f_projected;
  remove_rigid_motion(x, diff);
  EXPECT_LT(diff.cwiseAbs().maxCoeff(), 1e-12 * scale);
}
