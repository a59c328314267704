#pragma once
// Test support shared by the energy-based methods (A, B): irregular test meshes and the checks
// that the analytic force is minus the gradient of the energy and obeys the model's symmetries.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "bendlab/bending/bending_method.hpp"
#include "bendlab/geometry/measures.hpp"
#include "bendlab/geometry/mesh_geometry.hpp"
#include "bendlab/mesh/generators.hpp"
#include "bendlab/surfaces/analytic_surface.hpp"

namespace bendlab::test_support {

// An MT1 sphere whose nodes are moved by up to `fraction` of the mean edge length in each
// coordinate (fixed seed; the raw engine output keeps the numbers the same on every platform).
inline TriMesh perturbed_sphere(int level, double fraction, unsigned seed = 12345) {
  const TriMesh m = sphere_mesh(MeshFamily::MT1, level);
  const double h = mean_edge_length(m.topology(), m.positions());
  std::mt19937 gen(seed);
  Points x = m.positions();
  for (int i = 0; i < x.rows(); ++i)
    for (int c = 0; c < 3; ++c) x(i, c) += fraction * h * (2.0 * gen() / 4294967295.0 - 1.0);
  return m.with_positions(x);
}

// An MT1 sphere with 80 triangles, one Rivara pass, mapped to the RBC: irregular valences,
// obtuse triangles (where the Voronoi area of eq. (9) is not the mixed area) and strongly
// varying curvature.
inline TriMesh rivara_rbc() {
  const TriMesh m = rivara_pass(sphere_mesh(MeshFamily::MT1, 1));
  return m.with_positions(make_rbc()->map_from_unit_sphere(m.positions()));
}

// Fourth-order central difference of the energy in coordinate (i, c), step h.
inline double fd_gradient(const BendingMethod& method, const Topology& t, Points& x, int i, int c, double h) {
  const double x0 = x(i, c);
  auto energy_at = [&](double v) {
    x(i, c) = v;
    return *method.energy(t, x, 1.0);
  };
  const double d = (-energy_at(x0 + 2 * h) + 8 * energy_at(x0 + h) - 8 * energy_at(x0 - h) + energy_at(x0 - 2 * h)) /
                   (12 * h);
  x(i, c) = x0;
  return d;
}

// Compares F with -grad E on a sample of about 40 vertices: the relative norm of the difference
// over the sample, and every component against the largest force of the sample.
inline void expect_force_is_minus_gradient(const BendingMethod& method, const TriMesh& mesh, double tol = 1e-6) {
  const Topology& t = mesh.topology();
  Points x = mesh.positions();
  Points F;
  method.forces(t, x, 1.0, F);
  const double h = 1e-3 * mean_edge_length(t, x);
  const int n = t.num_vertices(), stride = std::max(1, n / 40);
  double diff2 = 0, norm2 = 0, fmax = 0;
  std::vector<std::pair<double, double>> pairs;
  for (int i = 0; i < n; i += stride) {
    fmax = std::max(fmax, F.row(i).norm());
    for (int c = 0; c < 3; ++c) {
      const double fd = -fd_gradient(method, t, x, i, c, h);
      diff2 += (fd - F(i, c)) * (fd - F(i, c));
      norm2 += F(i, c) * F(i, c);
      pairs.emplace_back(fd, F(i, c));
    }
  }
  ASSERT_GT(norm2, 0.0);
  EXPECT_LT(std::sqrt(diff2 / norm2), tol);
  for (const auto& [fd, an] : pairs) EXPECT_NEAR(fd, an, tol * fmax);
}

// Sum of F and of x x F, relative to sum |F| and sum |x| |F|.
inline void expect_translation_and_rotation_invariance(const BendingMethod& method, const TriMesh& mesh) {
  Points F;
  method.forces(mesh.topology(), mesh.positions(), 1.0, F);
  Vec3 total = Vec3::Zero(), torque = Vec3::Zero();
  double fsum = 0, tsum = 0;
  for (int i = 0; i < F.rows(); ++i) {
    const Vec3 f = row(F, i), xi = mesh.position(i);
    total += f;
    torque += xi.cross(f);
    fsum += f.norm();
    tsum += xi.norm() * f.norm();
  }
  EXPECT_LT(total.norm(), 1e-13 * fsum);
  EXPECT_LT(torque.norm(), 1e-13 * tsum);
}

// E(R x + b) = E(x) and F(R x + b) = R F(x); E(s x) = E(x) and F(s x) = F(x) / s.
inline void expect_rigid_and_scale_behaviour(const BendingMethod& method, const TriMesh& mesh) {
  const Topology& t = mesh.topology();
  const Points& x = mesh.positions();
  const Mat3 R = Eigen::AngleAxisd(0.7, Vec3(1, -2, 0.5).normalized()).toRotationMatrix();
  const Eigen::RowVector3d b(0.3, -1.1, 2.5);
  const Points moved = (x * R.transpose()).rowwise() + b;
  const double s = 3.7;
  const Points scaled = s * x;
  const double E = *method.energy(t, x, 1.0);
  EXPECT_NEAR(*method.energy(t, moved, 1.0), E, 1e-12 * E);
  EXPECT_NEAR(*method.energy(t, scaled, 1.0), E, 1e-12 * E);
  Points F, Fm, Fs;
  method.forces(t, x, 1.0, F);
  method.forces(t, moved, 1.0, Fm);
  method.forces(t, scaled, 1.0, Fs);
  const double scale = F.norm();
  EXPECT_LT((Fm - F * R.transpose()).norm(), 1e-12 * scale);
  EXPECT_LT((s * Fs - F).norm(), 1e-12 * scale);
}

}  // namespace bendlab::test_support
