#pragma once
// Stokes single-layer potential on a closed surface of flat triangles: the integral of the
// boundary integral equation (22), with the sign of docs/conventions.md §1 (traction jump
// Delta f^h = -f):
//
//   u_j(x_i) = 1/(8 pi mu) oint_S f_k(y) G_kj(y, x_i) dS(y),  G_kj = delta_kj / r + r_k r_j / r^3,
//   r = y - x_i,
//
// evaluated at every node x_i (the imposed flow u_inf is not included). f is the membrane force
// density given at the nodes and interpolated linearly over each triangle [43].
// - Triangles that do not contain x_i: the 7-point Gauss rule of degree 5 (Strang-Fix / Dunavant [117]).
// - Triangles that contain x_i: polar coordinates (rho, phi) centred on x_i [118]. There
//   G dS = (I + e e^T) / rho * rho drho dphi, the singularity cancels, and with f linear along
//   each ray the radial integral is exact: int_0^rho_max f drho = rho_max (f(x_i) + f_edge(phi)) / 2.
//   The angle is integrated by Gauss-Legendre on `angular_subdivisions` equal sub-angles
//   (sub-triangles at the singular vertex) of `angular_points` points each.
// All quadrature points, weights and interpolated densities are precomputed once per evaluation
// in structure-of-arrays form; the loop over targets runs in parallel (OpenMP).
#include <vector>

#include "bendlab/core/types.hpp"
#include "bendlab/mesh/topology.hpp"

namespace bendlab {

struct SingleLayerOptions {
  int angular_points = 8;        ///< Gauss-Legendre points per sub-angle of a singular triangle
  int angular_subdivisions = 2;  ///< sub-angles per singular triangle
};

class StokesSingleLayer {
 public:
  explicit StokesSingleLayer(TopologyPtr topology, SingleLayerOptions options = {});

  /// u (N x 3, resized if needed) = single-layer velocity at every node for node positions x and
  /// node force densities f_density (both N x 3), viscosity mu. Not for concurrent use of one object.
  void velocity(const Points& x, const Points& f_density, double mu, Points& u) const;

  const Topology& topology() const { return *topology_; }

 private:
  TopologyPtr topology_;
  SingleLayerOptions options_;
  std::vector<double> gl_nodes_, gl_weights_;  // Gauss-Legendre on [0, 1]
  // Quadrature points (7 per face, face-major) and the density times the weight times the area.
  mutable std::vector<double> qx_, qy_, qz_, fx_, fy_, fz_;
};

/// The 7-point degree-5 rule on a triangle: barycentric coordinates (of corners 0, 1, 2) and
/// weights summing to 1 (multiply by the area).
struct TriangleRule7 {
  static constexpr int size = 7;
  double bary[7][3];
  double weight[7];
};
const TriangleRule7& triangle_rule7();

/// Gauss-Legendre nodes and weights on [0, 1] (n >= 1).
void gauss_legendre_unit(int n, std::vector<double>& nodes, std::vector<double>& weights);

}  // namespace bendlab
