#include "bendlab/geometry/measures.hpp"

#include <algorithm>
#include <cmath>

namespace bendlab {

double surface_area(const Topology& t, const Points& x) {
  const Faces& F = t.faces();
  double s = 0;
  for (int f = 0; f < t.num_faces(); ++f) {
    const Vec3 a = x.row(F(f, 0)), b = x.row(F(f, 1)), c = x.row(F(f, 2));
    s += 0.5 * (b - a).cross(c - a).norm();
  }
  return s;
}

Vec3 volume_centroid(const Topology& t, const Points& x) {
  // Each face spans a tetrahedron with the origin; its centroid is (a+b+c)/4, its signed volume
  // a.(b x c)/6. Summing is exact for the polyhedron.
  const Faces& F = t.faces();
  Vec3 m = Vec3::Zero();
  double v = 0;
  for (int f = 0; f < t.num_faces(); ++f) {
    const Vec3 a = x.row(F(f, 0)), b = x.row(F(f, 1)), c = x.row(F(f, 2));
    const double vf = a.dot(b.cross(c)) / 6.0;
    v += vf;
    m += vf * (a + b + c) / 4.0;
  }
  return m / v;
}

double mean_edge_length(const Topology& t, const Points& x) {
  const IndexPairs& E = t.edge_vertices();
  double s = 0;
  for (int e = 0; e < t.num_edges(); ++e) s += (x.row(E(e, 0)) - x.row(E(e, 1))).norm();
  return s / t.num_edges();
}

double min_corner_angle(const Topology& t, const Points& x) {
  const Faces& F = t.faces();
  double m = M_PI;
  for (int f = 0; f < t.num_faces(); ++f)
    for (int k = 0; k < 3; ++k) {
      const Vec3 p = x.row(F(f, k)), u = Vec3(x.row(F(f, (k + 1) % 3))) - p, w = Vec3(x.row(F(f, (k + 2) % 3))) - p;
      m = std::min(m, std::atan2(u.cross(w).norm(), u.dot(w)));
    }
  return m;
}

ValenceStats valence_stats(const Topology& t) {
  ValenceStats s;
  s.min = t.valence(0);
  s.max = t.valence(0);
  for (int i = 0; i < t.num_vertices(); ++i) {
    s.min = std::min(s.min, t.valence(i));
    s.max = std::max(s.max, t.valence(i));
  }
  s.histogram.assign(s.max + 1, 0);
  for (int i = 0; i < t.num_vertices(); ++i) ++s.histogram[t.valence(i)];
  s.mean = static_cast<double>(t.ring_vertices().size()) / t.num_vertices();
  return s;
}

}  // namespace bendlab
