#include "bendlab/geometry/mesh_geometry.hpp"

#include <cmath>

namespace bendlab {

MeshGeometry MeshGeometry::compute(const Topology& t, const Points& x) {
  const int nf = t.num_faces(), nv = t.num_vertices(), ne = t.num_edges();
  const Faces& F = t.faces();
  MeshGeometry g;
  g.face_area.resize(nf);
  g.face_normal.resize(nf, 3);
  g.corner_angle.resize(nf, 3);
  g.corner_cot.resize(nf, 3);
  g.edge_cot_weight = Scalars::Zero(ne);
  g.voronoi_area = Scalars::Zero(nv);
  g.mixed_area = Scalars::Zero(nv);
  g.angle_sum = Scalars::Zero(nv);
  g.normal_mwa = Points::Zero(nv, 3);

  for (int f = 0; f < nf; ++f) {
    const Vec3 p[3] = {x.row(F(f, 0)), x.row(F(f, 1)), x.row(F(f, 2))};
    const Vec3 n2 = (p[1] - p[0]).cross(p[2] - p[0]);  // twice the area times the unit normal
    const double two_area = n2.norm();
    g.face_area[f] = 0.5 * two_area;
    g.face_normal.row(f) = n2 / two_area;
    for (int k = 0; k < 3; ++k) {
      const Vec3 u = p[(k + 1) % 3] - p[k], w = p[(k + 2) % 3] - p[k];
      const double d = u.dot(w);
      g.corner_cot(f, k) = d / two_area;  // |u x w| = twice the area for every corner
      g.corner_angle(f, k) = std::atan2(two_area, d);
    }
    for (int k = 0; k < 3; ++k) {
      g.edge_cot_weight[t.face_edges()(f, k)] += g.corner_cot(f, k);
      const int i = F(f, k);
      g.angle_sum[i] += g.corner_angle(f, k);
      g.normal_mwa.row(i) += g.corner_angle(f, k) * g.face_normal.row(f);
      // Voronoi part of corner k: the two edges at k, each weighted by the cotangent opposite it.
      const double l_next2 = (p[(k + 1) % 3] - p[k]).squaredNorm();  // edge opposite corner k+2
      const double l_prev2 = (p[(k + 2) % 3] - p[k]).squaredNorm();  // edge opposite corner k+1
      const double vor = (l_next2 * g.corner_cot(f, (k + 2) % 3) + l_prev2 * g.corner_cot(f, (k + 1) % 3)) / 8.0;
      g.voronoi_area[i] += vor;
    }
    // Mixed area (Meyer et al. 2002, fig. 4).
    int obtuse = -1;
    for (int k = 0; k < 3; ++k)
      if (g.corner_cot(f, k) < 0) obtuse = k;
    for (int k = 0; k < 3; ++k) {
      const int i = F(f, k);
      if (obtuse < 0) {
        const double l_next2 = (p[(k + 1) % 3] - p[k]).squaredNorm();
        const double l_prev2 = (p[(k + 2) % 3] - p[k]).squaredNorm();
        g.mixed_area[i] += (l_next2 * g.corner_cot(f, (k + 2) % 3) + l_prev2 * g.corner_cot(f, (k + 1) % 3)) / 8.0;
      } else {
        g.mixed_area[i] += (k == obtuse ? 0.5 : 0.25) * g.face_area[f];
      }
    }
  }
  g.gaussian_curvature.resize(nv);
  for (int i = 0; i < nv; ++i) {
    g.normal_mwa.row(i).normalize();
    g.gaussian_curvature[i] = (2 * M_PI - g.angle_sum[i]) / g.mixed_area[i];
  }
  return g;
}

Scalars cotan_laplacian(const Topology& t, const MeshGeometry& g, const Scalars& w, const Scalars& area) {
  const int nv = t.num_vertices();
  Scalars out(nv);
  const auto& ring = t.ring_vertices();
  const auto& redge = t.ring_edges();
#pragma omp parallel for schedule(static)
  for (int i = 0; i < nv; ++i) {
    double s = 0;
    for (int k = t.ring_begin(i); k < t.ring_end(i); ++k) s += g.edge_cot_weight[redge[k]] * (w[ring[k]] - w[i]);
    out[i] = s / (2 * area[i]);
  }
  return out;
}

Points cotan_laplacian(const Topology& t, const MeshGeometry& g, const Points& w, const Scalars& area) {
  const int nv = t.num_vertices();
  Points out(nv, 3);
  const auto& ring = t.ring_vertices();
  const auto& redge = t.ring_edges();
#pragma omp parallel for schedule(static)
  for (int i = 0; i < nv; ++i) {
    Eigen::RowVector3d s = Eigen::RowVector3d::Zero();
    for (int k = t.ring_begin(i); k < t.ring_end(i); ++k)
      s += g.edge_cot_weight[redge[k]] * (w.row(ring[k]) - w.row(i));
    out.row(i) = s / (2 * area[i]);
  }
  return out;
}

Scalars mean_curvature_cotan(const Topology& t, const MeshGeometry& g, const Points& x, const Points& normals,
                             const Scalars& area) {
  const Points lap = cotan_laplacian(t, g, x, area);
  Scalars H(t.num_vertices());
  for (int i = 0; i < t.num_vertices(); ++i) H[i] = -0.5 * lap.row(i).dot(normals.row(i));
  return H;
}

}  // namespace bendlab
