#pragma once
// Discrete differential geometry of flat triangles, computed in one pass for one set of positions
// and kept together so that every bending method reads the same numbers.
//
// Conventions (see docs/conventions.md of the specification):
// - face normals are unit and outward (faces counter-clockwise seen from outside);
// - corner k of face f is at vertex faces(f, k); corner_angle(f, k) in (0, pi);
// - edge_cot_weight(e) = T_ij = cot(theta_1) + cot(theta_2), the cotangents of the two corners
//   opposite edge e (paper eq. (A.3));
// - voronoi_area = eq. (9), taken for every triangle, obtuse or not (Method B);
// - mixed_area = Meyer et al.'s mixed area: Voronoi part in non-obtuse triangles, A/2 to an obtuse
//   corner and A/4 to the other two corners of an obtuse triangle; the mixed areas tile the surface;
// - normal_mwa = "mean weighted by angle": sum of face normals weighted by the corner angle, unit;
// - gaussian_curvature = angle defect (2 pi - sum of corner angles) / mixed area, eq. (12).
#include "bendlab/core/types.hpp"
#include "bendlab/mesh/topology.hpp"

namespace bendlab {

using CornerValues = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;

struct MeshGeometry {
  Scalars face_area;            ///< F
  Points face_normal;           ///< F x 3, unit, outward
  CornerValues corner_angle;    ///< F x 3, radians
  CornerValues corner_cot;      ///< F x 3, cotangent of corner_angle
  Scalars edge_cot_weight;      ///< E, T_ij of eq. (A.3)
  Scalars voronoi_area;         ///< N, eq. (9)
  Scalars mixed_area;           ///< N, Meyer's mixed area
  Scalars angle_sum;            ///< N, sum of the corner angles at the vertex
  Points normal_mwa;            ///< N x 3, unit
  Scalars gaussian_curvature;   ///< N, eq. (12)
  CornerValues corner_voronoi;  ///< F x 3, each corner's share of voronoi_area
  CornerValues corner_mixed;    ///< F x 3, each corner's share of mixed_area

  static MeshGeometry compute(const Topology& topology, const Points& x);
  /// The same into `out`, reusing its arrays (no allocation when they already have the mesh's sizes).
  static void compute(const Topology& topology, const Points& x, MeshGeometry& out);
};

/// Meyer's mixed area alone: MeshGeometry::compute(topology, x).mixed_area, bit for bit (tested),
/// without the angles, normals and edge weights (for methods that need only the area, e.g. S).
Scalars mixed_area(const Topology& topology, const Points& x);
/// The same into `area`, with the per-corner shares in `corner_mixed` (both reused).
void mixed_area(const Topology& topology, const Points& x, Scalars& area, CornerValues& corner_mixed);

/// Cotangent Laplace-Beltrami of a per-vertex scalar, with the div-grad sign (negative
/// semidefinite): (Lap w)_i = 1/(2 A_i) sum_j T_ij (w_j - w_i), eq. (11) with A_i = area(i).
/// With area = mixed_area this is Meyer's operator; with voronoi_area it is eq. (7).
Scalars cotan_laplacian(const Topology& topology, const MeshGeometry& geometry, const Scalars& w,
                        const Scalars& area);
/// The same operator applied to each column of a per-vertex vector field (e.g. positions).
Points cotan_laplacian(const Topology& topology, const MeshGeometry& geometry, const Points& w,
                       const Scalars& area);
/// Both into `out` (resized; no allocation when it has the size already).
void cotan_laplacian(const Topology& topology, const MeshGeometry& geometry, const Scalars& w, const Scalars& area,
                     Scalars& out);
void cotan_laplacian(const Topology& topology, const MeshGeometry& geometry, const Points& w, const Scalars& area,
                     Points& out);

/// Mean curvature from eq. (2) with the cotangent Laplacian: H_i = -1/2 (Lap x)_i . n_i, positive
/// on a sphere (Lap x = -2 H n).
Scalars mean_curvature_cotan(const Topology& topology, const MeshGeometry& geometry, const Points& x,
                             const Points& normals, const Scalars& area);
/// The same into `H`, with Lap x in `lap_x` (both reused).
void mean_curvature_cotan(const Topology& topology, const MeshGeometry& geometry, const Points& x,
                          const Points& normals, const Scalars& area, Points& lap_x, Scalars& H);

}  // namespace bendlab
