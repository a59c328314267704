#include "bendlab/geometry/mesh_geometry.hpp"

#include <cmath>

namespace bendlab {

MeshGeometry MeshGeometry::compute(const Topology& t, const Points& x) {
  MeshGeometry g;
  compute(t, x, g);
  return g;
}

void MeshGeometry::compute(const Topology& t, const Points& x, MeshGeometry& g) {
  const int nf = t.num_faces(), nv = t.num_vertices(), ne = t.num_edges();
  const Faces& F = t.faces();
  g.face_area.resize(nf);
  g.face_normal.resize(nf, 3);
  g.corner_angle.resize(nf, 3);
  g.corner_cot.resize(nf, 3);
  g.edge_cot_weight.resize(ne);
  g.voronoi_area.resize(nv);
  g.mixed_area.resize(nv);
  g.angle_sum.resize(nv);
  g.normal_mwa.resize(nv, 3);
  g.gaussian_curvature.resize(nv);
  // Each corner's share of the Voronoi and of the mixed area, gathered per vertex below.
  g.corner_voronoi.resize(nf, 3);
  g.corner_mixed.resize(nf, 3);
  CornerValues& corner_voronoi = g.corner_voronoi;
  CornerValues& corner_mixed = g.corner_mixed;

  // Three passes, each free of write conflicts (faces, then edges, then vertices gathering over
  // their CSR ring), so they run in parallel and sum in the same order for any thread count.
#pragma omp parallel for schedule(static)
  for (int f = 0; f < nf; ++f) {
    const Vec3 p[3] = {x.row(F(f, 0)), x.row(F(f, 1)), x.row(F(f, 2))};
    const Vec3 n2 = (p[1] - p[0]).cross(p[2] - p[0]);  // twice the area times the unit normal
    const double two_area = n2.norm();
    g.face_area[f] = 0.5 * two_area;
    g.face_normal.row(f) = n2 / two_area;
    double l2[3];  // l2[k] = squared length of the edge opposite corner k
    for (int k = 0; k < 3; ++k) {
      const Vec3 u = p[(k + 1) % 3] - p[k], w = p[(k + 2) % 3] - p[k];
      g.corner_cot(f, k) = u.dot(w) / two_area;  // |u x w| = twice the area for every corner
      l2[k] = (p[(k + 2) % 3] - p[(k + 1) % 3]).squaredNorm();
    }
    // Two angles from atan2 (accurate for any shape), the third from the angle sum: atan2 is the
    // most expensive operation of the pass. The largest angle is the one derived, so its
    // absolute rounding error (a few ulp of pi) stays small relative to it.
    int big = 0;
    for (int k = 1; k < 3; ++k)
      if (g.corner_cot(f, k) < g.corner_cot(f, big)) big = k;
    double sum = 0;
    for (int k = 0; k < 3; ++k)
      if (k != big) sum += g.corner_angle(f, k) = std::atan2(1.0, g.corner_cot(f, k));
    g.corner_angle(f, big) = M_PI - sum;
    int obtuse = -1;
    for (int k = 0; k < 3; ++k)
      if (g.corner_cot(f, k) < 0) obtuse = k;
    for (int k = 0; k < 3; ++k) {
      // Voronoi part of corner k, eq. (9): its two edges, each weighted by the cotangent opposite it.
      const int k1 = (k + 1) % 3, k2 = (k + 2) % 3;
      corner_voronoi(f, k) = (l2[k2] * g.corner_cot(f, k2) + l2[k1] * g.corner_cot(f, k1)) / 8.0;
      // Mixed area (Meyer et al. 2002, fig. 4): Voronoi in non-obtuse triangles, else A/2 to the
      // obtuse corner and A/4 to the others.
      corner_mixed(f, k) = obtuse < 0 ? corner_voronoi(f, k) : (k == obtuse ? 0.5 : 0.25) * g.face_area[f];
    }
  }

  const IndexPairs& ef = t.edge_faces();
  const IndexPairs& ec = t.edge_opposite_corners();
#pragma omp parallel for schedule(static)
  for (int e = 0; e < ne; ++e) g.edge_cot_weight[e] = g.corner_cot(ef(e, 0), ec(e, 0)) + g.corner_cot(ef(e, 1), ec(e, 1));

  const auto& rf = t.ring_faces();
  const auto& rc = t.ring_corners();
#pragma omp parallel for schedule(static)
  for (int i = 0; i < nv; ++i) {
    double angle = 0, voronoi = 0, mixed = 0;
    Eigen::RowVector3d n = Eigen::RowVector3d::Zero();
    for (int r = t.ring_begin(i); r < t.ring_end(i); ++r) {
      const int f = rf[r], c = rc[r];
      angle += g.corner_angle(f, c);
      n += g.corner_angle(f, c) * g.face_normal.row(f);
      voronoi += corner_voronoi(f, c);
      mixed += corner_mixed(f, c);
    }
    g.angle_sum[i] = angle;
    g.normal_mwa.row(i) = n.normalized();
    g.voronoi_area[i] = voronoi;
    g.mixed_area[i] = mixed;
    g.gaussian_curvature[i] = (2 * M_PI - angle) / mixed;  // eq. (12)
  }
}

Scalars mixed_area(const Topology& t, const Points& x) {
  Scalars area;
  CornerValues corner_mixed;
  mixed_area(t, x, area, corner_mixed);
  return area;
}

void mixed_area(const Topology& t, const Points& x, Scalars& area, CornerValues& corner_mixed) {
  const int nf = t.num_faces(), nv = t.num_vertices();
  const Faces& F = t.faces();
  // The arithmetic of MeshGeometry::compute, step for step.
  corner_mixed.resize(nf, 3);
#pragma omp parallel for schedule(static)
  for (int f = 0; f < nf; ++f) {
    const Vec3 p[3] = {x.row(F(f, 0)), x.row(F(f, 1)), x.row(F(f, 2))};
    const double two_area = (p[1] - p[0]).cross(p[2] - p[0]).norm();
    const double face_area = 0.5 * two_area;
    double cot[3], l2[3];
    for (int k = 0; k < 3; ++k) {
      const Vec3 u = p[(k + 1) % 3] - p[k], w = p[(k + 2) % 3] - p[k];
      cot[k] = u.dot(w) / two_area;
      l2[k] = (p[(k + 2) % 3] - p[(k + 1) % 3]).squaredNorm();
    }
    int obtuse = -1;
    for (int k = 0; k < 3; ++k)
      if (cot[k] < 0) obtuse = k;
    for (int k = 0; k < 3; ++k) {
      const int k1 = (k + 1) % 3, k2 = (k + 2) % 3;
      corner_mixed(f, k) = obtuse < 0 ? (l2[k2] * cot[k2] + l2[k1] * cot[k1]) / 8.0
                                      : (k == obtuse ? 0.5 : 0.25) * face_area;
    }
  }
  const auto& rf = t.ring_faces();
  const auto& rc = t.ring_corners();
  area.resize(nv);
#pragma omp parallel for schedule(static)
  for (int i = 0; i < nv; ++i) {
    double mixed = 0;
    for (int r = t.ring_begin(i); r < t.ring_end(i); ++r) mixed += corner_mixed(rf[r], rc[r]);
    area[i] = mixed;
  }
}

Scalars cotan_laplacian(const Topology& t, const MeshGeometry& g, const Scalars& w, const Scalars& area) {
  Scalars out;
  cotan_laplacian(t, g, w, area, out);
  return out;
}

void cotan_laplacian(const Topology& t, const MeshGeometry& g, const Scalars& w, const Scalars& area, Scalars& out) {
  const int nv = t.num_vertices();
  out.resize(nv);
  const auto& ring = t.ring_vertices();
  const auto& redge = t.ring_edges();
#pragma omp parallel for schedule(static)
  for (int i = 0; i < nv; ++i) {
    double s = 0;
    for (int k = t.ring_begin(i); k < t.ring_end(i); ++k) s += g.edge_cot_weight[redge[k]] * (w[ring[k]] - w[i]);
    out[i] = s / (2 * area[i]);
  }
}

Points cotan_laplacian(const Topology& t, const MeshGeometry& g, const Points& w, const Scalars& area) {
  Points out;
  cotan_laplacian(t, g, w, area, out);
  return out;
}

void cotan_laplacian(const Topology& t, const MeshGeometry& g, const Points& w, const Scalars& area, Points& out) {
  const int nv = t.num_vertices();
  out.resize(nv, 3);
  const auto& ring = t.ring_vertices();
  const auto& redge = t.ring_edges();
#pragma omp parallel for schedule(static)
  for (int i = 0; i < nv; ++i) {
    Eigen::RowVector3d s = Eigen::RowVector3d::Zero();
    for (int k = t.ring_begin(i); k < t.ring_end(i); ++k)
      s += g.edge_cot_weight[redge[k]] * (w.row(ring[k]) - w.row(i));
    out.row(i) = s / (2 * area[i]);
  }
}

Scalars mean_curvature_cotan(const Topology& t, const MeshGeometry& g, const Points& x, const Points& normals,
                             const Scalars& area) {
  Points lap;
  Scalars H;
  mean_curvature_cotan(t, g, x, normals, area, lap, H);
  return H;
}

void mean_curvature_cotan(const Topology& t, const MeshGeometry& g, const Points& x, const Points& normals,
                          const Scalars& area, Points& lap, Scalars& H) {
  cotan_laplacian(t, g, x, area, lap);
  H.resize(t.num_vertices());
  for (int i = 0; i < t.num_vertices(); ++i) H[i] = -0.5 * lap.row(i).dot(normals.row(i));
}

}  // namespace bendlab
