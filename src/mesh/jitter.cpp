#include "bendlab/mesh/jitter.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>

namespace bendlab {

Scalars mean_incident_edge_length(const TriMesh& mesh) {
  const Topology& t = mesh.topology();
  Scalars sum = Scalars::Zero(mesh.num_vertices());
  Eigen::VectorXi count = Eigen::VectorXi::Zero(mesh.num_vertices());
  for (int e = 0; e < t.num_edges(); ++e) {
    const int a = t.edge_vertices()(e, 0), b = t.edge_vertices()(e, 1);
    const double len = (mesh.position(a) - mesh.position(b)).norm();
    sum[a] += len, sum[b] += len;
    ++count[a], ++count[b];
  }
  return sum.array() / count.cast<double>().array();  // closed meshes: every node has edges
}

namespace {

// t1 of the header: perpendicular to x, built from the coordinate axis least aligned with it.
Vec3 first_tangent(const Vec3& x) {
  int k = 0;
  for (int j = 1; j < 3; ++j)
    if (std::abs(x[j]) < std::abs(x[k])) k = j;
  return x.cross(Vec3::Unit(k)).normalized();
}

}  // namespace

Points jitter_tangential(const TriMesh& sphere, double fraction, std::uint64_t seed) {
  if (!(fraction >= 0) || !std::isfinite(fraction))
    throw Error(fmt::format("jitter fraction must be finite and >= 0, got {}", fraction));
  const Scalars l = mean_incident_edge_length(sphere);
  std::mt19937_64 g(seed);
  Points y = sphere.positions();
  for (int i = 0; i < sphere.num_vertices(); ++i) {
    const Vec3 x = sphere.position(i);
    const Vec3 t1 = first_tangent(x), t2 = x.cross(t1).normalized();
    const double phi = 2 * std::numbers::pi * static_cast<double>(g() >> 11) * 0x1.0p-53;
    y.row(i) += (fraction * l[i] * (std::cos(phi) * t1 + std::sin(phi) * t2)).transpose();
  }
  return y;
}

int first_folded_face(const Faces& faces, const Points& x) {
  for (Eigen::Index f = 0; f < faces.rows(); ++f) {
    const Vec3 a = x.row(faces(f, 0)).transpose(), b = x.row(faces(f, 1)).transpose(),
               c = x.row(faces(f, 2)).transpose();
    const Vec3 n = (b - a).cross(c - a);
    const double longest2 = std::max({(b - a).squaredNorm(), (c - b).squaredNorm(), (a - c).squaredNorm()});
    if (n.dot(a + b + c) <= 0 || n.norm() <= 1e-12 * longest2) return static_cast<int>(f);
  }
  return -1;
}

TriMesh jitter_sphere(const TriMesh& sphere, double fraction, std::uint64_t seed) {
  Points y = jitter_tangential(sphere, fraction, seed);
  for (Eigen::Index i = 0; i < y.rows(); ++i) y.row(i).normalize();
  const int f = first_folded_face(sphere.faces(), y);
  if (f >= 0)
    throw Error(fmt::format("jitter fraction {} folds triangle {} of the {}-triangle sphere mesh (seed {}): its "
                            "normal no longer points outward or it is degenerate; use a smaller fraction",
                            fraction, f, sphere.num_faces(), seed));
  return TriMesh(sphere.topology_ptr(), std::move(y));
}

}  // namespace bendlab
