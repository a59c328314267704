#include "bendlab/bending/julicher.hpp"

#include <cmath>
#include <limits>
#include <vector>

#include "bendlab/geometry/mesh_geometry.hpp"

namespace bendlab {

namespace {

// Per-vertex sums of one shape: M_i = sum_e l_e theta_e and the barycentric area A_i.
struct Sums {
  Scalars M, A;
};

// The kernel's arrays (reused from call to call).
struct JulicherScratch {
  Points normal;  // unit face normals
  Scalars area;   // face areas
  Scalars len, theta;
  Sums sums;
  Scalars alpha, beta;
  Points ga, gb, go0, go1;
  Scalars gface;
};

// The derivation. With M_i = sum_{e at i} l_e theta_e and A_i as in the header,
//   E = kB/8 sum_i M_i^2 / A_i,   dE = sum_i alpha_i dM_i - beta_i dA_i,
//   alpha_i = kB M_i / (4 A_i) = kB H_i,   beta_i = kB M_i^2 / (8 A_i^2) = 2 kB H_i^2.
// Collecting per edge e = (a, b) the weight w_e = alpha_a + alpha_b and per face f the weight
// g_f = (beta of its three corners) / 3:
//   dE = sum_e w_e (theta_e dl_e + l_e dtheta_e) - sum_f g_f dA_f.
// Lengths and areas: dl_e/da = (a - b)/l_e; dA_f/dx_k = 1/2 n_f x (x_{k+2} - x_{k+1}) for corner k
// of a counter-clockwise face.
// Dihedral angle: theta_e = atan2((n0 x n1) . (b - a)/l, n0 . n1), n0, n1 the unit normals of the
// faces f0 (a -> b) and f1 (b -> a), o0, o1 their vertices off the edge. Only the rotation of each
// face about the edge changes theta to first order; face f_k turns by (height change of o_k over
// the edge) / h_k, h_k = 2 A_k / l its height, and lifting o_k along n_k flattens the edge:
//   dtheta/do_k = -n_k / h_k,
//   dtheta/da   = sum_k (1 - t_k) n_k / h_k,   dtheta/db = sum_k t_k n_k / h_k,
// with t_k = (o_k - a) . (b - a) / l^2 the foot of o_k's height on the edge (the four gradients
// sum to zero, and the rotation about the edge leaves no torque).
//
// With c0 and ADE (docs/conventions.md §5): E = 2 kB sum_i (H_i - c0)^2 A_i + E_ADE(M), with the
// discrete M = sum_i H_i A_i = 1/4 sum_i M_i = 1/2 sum_e l_e theta_e, so only the weights change:
//   alpha_i = kB (H_i - c0) + lambda / 4,   beta_i = 2 kB (H_i^2 - c0^2),
// lambda = alpha pi kB (M - M0) / A (BendingParameters::ade_lambda). Plain parameters keep the
// expressions above, operation for operation.
// Returns the energy; fills *force when given; the per-vertex sums are left in ws.sums.
double kernel(const Topology& t, const Points& x, const BendingParameters& p, Points* force, JulicherScratch& ws) {
  const double kappa_b = p.kappa_b;
  const bool plain = p.plain();
  const int nf = t.num_faces(), nv = t.num_vertices(), ne = t.num_edges();
  const Faces& F = t.faces();
  const IndexPairs& EV = t.edge_vertices();
  const IndexPairs& EF = t.edge_faces();
  const IndexPairs& EO = t.edge_opposite();
  const auto& roff = t.ring_offsets();
  const auto& rfaces = t.ring_faces();
  const auto& redges = t.ring_edges();
  const auto& rcorners = t.ring_corners();
  const Faces& FE = t.face_edges();

  Points& normal = ws.normal;  // unit face normals
  Scalars& area = ws.area;     // face areas
  Scalars& len = ws.len;
  Scalars& theta = ws.theta;
  normal.resize(nf, 3);
  area.resize(nf);
  len.resize(ne);
  theta.resize(ne);
  Sums& s = ws.sums;
  s.M.resize(nv);
  s.A.resize(nv);
  double energy = 0;
  const bool par = nf >= kBendingParallelMinFaces;

#pragma omp parallel if (par)
  {
#pragma omp for schedule(static)
    for (int f = 0; f < nf; ++f) {
      const Vec3 p0 = row(x, F(f, 0)), p1 = row(x, F(f, 1)), p2 = row(x, F(f, 2));
      const Vec3 m = (p1 - p0).cross(p2 - p0);
      const double l = m.norm();
      area[f] = 0.5 * l;
      normal.row(f) = (m / l).transpose();
    }
#pragma omp for schedule(static)
    for (int e = 0; e < ne; ++e) {
      const Vec3 d = row(x, EV(e, 1)) - row(x, EV(e, 0));
      const double l = d.norm();
      const Vec3 n0 = row(normal, EF(e, 0)), n1 = row(normal, EF(e, 1));
      len[e] = l;
      theta[e] = std::atan2(n0.cross(n1).dot(d) / l, n0.dot(n1));
    }
#pragma omp for schedule(static) reduction(+ : energy)
    for (int i = 0; i < nv; ++i) {
      double m = 0, a = 0;
      for (int r = roff[i]; r < roff[i + 1]; ++r) {
        m += len[redges[r]] * theta[redges[r]];
        a += area[rfaces[r]];
      }
      s.M[i] = m;
      s.A[i] = a / 3.0;
      energy += kappa_b / 8.0 * m * m / s.A[i];
    }
  }
  // The weights alpha_i, beta_i with c0 and ADE (unused when plain).
  Scalars& alpha = ws.alpha;
  Scalars& beta = ws.beta;
  if (!plain) {
    energy = 0;
    double mtot = 0;
    alpha.resize(nv);
    beta.resize(nv);
    for (int i = 0; i < nv; ++i) {
      const double h = s.M[i] / (4.0 * s.A[i]);
      energy += 2.0 * kappa_b * (h - p.c0) * (h - p.c0) * s.A[i];
      mtot += 0.25 * s.M[i];
      alpha[i] = kappa_b * (h - p.c0);
      beta[i] = 2.0 * kappa_b * (h * h - p.c0 * p.c0);
    }
    energy += p.ade_energy(mtot);
    const double lambda4 = 0.25 * p.ade_lambda(mtot);
    alpha.array() += lambda4;
  }
  if (force != nullptr) {
    force->resize(nv, 3);
    // Per edge: the weighted gradient of l_e theta_e w.r.t. a, b, o0, o1 (dE terms of the edge).
    Points& ga = ws.ga;
    Points& gb = ws.gb;
    Points& go0 = ws.go0;
    Points& go1 = ws.go1;
    Scalars& gface = ws.gface;
    ga.resize(ne, 3);
    gb.resize(ne, 3);
    go0.resize(ne, 3);
    go1.resize(ne, 3);
    gface.resize(nf);
#pragma omp parallel if (par)
    {
#pragma omp for schedule(static)
      for (int f = 0; f < nf; ++f) {
        if (!plain) {
          gface[f] = (beta[F(f, 0)] + beta[F(f, 1)] + beta[F(f, 2)]) / 3.0;  // g_f
          continue;
        }
        double b = 0;
        for (int k = 0; k < 3; ++k) {
          const int v = F(f, k);
          const double h = s.M[v] / s.A[v];
          b += h * h;
        }
        gface[f] = kappa_b / 8.0 * b / 3.0;  // g_f
      }
#pragma omp for schedule(static)
      for (int e = 0; e < ne; ++e) {
        const int a = EV(e, 0), b = EV(e, 1);
        const double w = plain ? kappa_b / 4.0 * (s.M[a] / s.A[a] + s.M[b] / s.A[b])  // w_e
                               : alpha[a] + alpha[b];
        const Vec3 pa = row(x, a), pb = row(x, b), d = pb - pa;
        const double l = len[e], l2 = l * l;
        Vec3 da = Vec3::Zero(), db = Vec3::Zero(), dok[2];
        for (int k = 0; k < 2; ++k) {
          const int f = EF(e, k);
          const Vec3 nk = row(normal, f);
          const double h = 2.0 * area[f] / l;
          const double tk = (row(x, EO(e, k)) - pa).dot(d) / l2;
          const Vec3 q = nk / h;
          dok[k] = -q;
          da += (1.0 - tk) * q;
          db += tk * q;
        }
        // d(l theta) = theta dl + l dtheta, weighted by w_e.
        const Vec3 dl_da = -d / l;
        ga.row(e) = (w * (theta[e] * dl_da + l * da)).transpose();
        gb.row(e) = (w * (-theta[e] * dl_da + l * db)).transpose();
        go0.row(e) = (w * l * dok[0]).transpose();
        go1.row(e) = (w * l * dok[1]).transpose();
      }
      // Gather per vertex: edges at i (as an end), the edge opposite i in each ring face (i is its
      // off-edge vertex there), and the areas of the ring faces.
#pragma omp for schedule(static)
      for (int i = 0; i < nv; ++i) {
        Vec3 g = Vec3::Zero();
        for (int r = roff[i]; r < roff[i + 1]; ++r) {
          const int e = redges[r];
          g += EV(e, 0) == i ? row(ga, e) : row(gb, e);
          const int f = rfaces[r], k = rcorners[r];
          const int eo = FE(f, k);
          g += EF(eo, 0) == f ? row(go0, eo) : row(go1, eo);
          const Vec3 dA = 0.5 * row(normal, f).cross(row(x, F(f, (k + 2) % 3)) - row(x, F(f, (k + 1) % 3)));
          g -= gface[f] * dA;
        }
        force->row(i) = -g.transpose();
      }
    }
  }
  return energy;
}

}  // namespace

// The kernel's arrays and compute()'s geometry, kept by the method instance and reused from call
// to call, so a time loop does not allocate (and page in) fresh memory at every step
// (method_workspace.hpp).
struct JulicherMethod::Workspace {
  JulicherScratch kernel;
  MeshGeometry geometry;
};

JulicherMethod::JulicherMethod() = default;
JulicherMethod::~JulicherMethod() = default;

std::unique_ptr<BendingMethod> JulicherMethod::create(const MethodOptions& options) {
  resolve_method_options(info(), options);  // J takes no options: refuses any
  return std::make_unique<JulicherMethod>();
}

MethodInfo JulicherMethod::info() {
  MethodInfo m{"J", "Juelicher: exact gradient of the edge-based (dihedral-angle) Helfrich energy (not in the paper)",
               {}, {}, &JulicherMethod::create};
  m.capabilities.has_energy = true;
  m.capabilities.defines_lapH = false;
  return m;
}

void JulicherMethod::forces(const Topology& t, const Points& x, double kappa_b, Points& force) const {
  kernel(t, x, BendingParameters(kappa_b), &force, workspace_.acquire()->kernel);
}

std::optional<double> JulicherMethod::energy(const Topology& t, const Points& x, double kappa_b) const {
  return kernel(t, x, BendingParameters(kappa_b), nullptr, workspace_.acquire()->kernel);
}

BendingResult JulicherMethod::compute(const Topology& t, const Points& x, double kappa_b) const {
  return compute_terms(t, x, BendingParameters(kappa_b));
}

void JulicherMethod::compute_into(const Topology& t, const Points& x, double kappa_b, BendingResult& out) const {
  compute_terms_into(t, x, BendingParameters(kappa_b), out);
}

void JulicherMethod::forces_terms(const Topology& t, const Points& x, const BendingParameters& p,
                                  Points& force) const {
  kernel(t, x, p, &force, workspace_.acquire()->kernel);
}

std::optional<double> JulicherMethod::energy_terms(const Topology& t, const Points& x,
                                                   const BendingParameters& p) const {
  return kernel(t, x, p, nullptr, workspace_.acquire()->kernel);
}

BendingResult JulicherMethod::compute_terms(const Topology& t, const Points& x, const BendingParameters& p) const {
  BendingResult r;
  compute_terms_into(t, x, p, r);
  return r;
}

void JulicherMethod::compute_terms_into(const Topology& t, const Points& x, const BendingParameters& p,
                                        BendingResult& r) const {
  const int nv = t.num_vertices();
  const auto ws = workspace_.acquire();
  r.energy = kernel(t, x, p, &r.force, ws->kernel);
  const Sums& s = ws->kernel.sums;
  MeshGeometry& g = ws->geometry;
  MeshGeometry::compute(t, x, g);
  r.H.resize(nv);
  r.K.resize(nv);
  r.normal.resize(nv, 3);
  r.force_density.resize(nv, 3);
  for (int i = 0; i < nv; ++i) {
    r.H[i] = s.M[i] / (4.0 * s.A[i]);
    r.K[i] = (2.0 * M_PI - g.angle_sum[i]) / s.A[i];
    Vec3 n = Vec3::Zero();
    for (int k = t.ring_begin(i); k < t.ring_end(i); ++k) {
      const int f = t.ring_faces()[k];
      n += g.face_area[f] * row(g.face_normal, f);
    }
    r.normal.row(i) = n.normalized().transpose();
    r.force_density.row(i) = r.force.row(i) / g.mixed_area[i];  // eq. (14)
  }
  r.area.swap(g.mixed_area);  // no copy; next call the arrays are reused
  r.lapH.setConstant(nv, std::numeric_limits<double>::quiet_NaN());
}

}  // namespace bendlab
