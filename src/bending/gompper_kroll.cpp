#include "bendlab/bending/gompper_kroll.hpp"

#include <cmath>
#include <limits>
#include <vector>

#include "bendlab/geometry/mesh_geometry.hpp"

namespace bendlab {

namespace {

// Per-vertex sums of eq. (A.2): S_i = sum_j T_ij (x_i - x_j) and D_i = sum_j T_ij l_ij^2 = 8 A_i.
struct VertexSums {
  Points S;
  Scalars D;
  Scalars m;  ///< with c0 / ADE only: m_i = H_i A_i = sign(S_i . N_i) |S_i| / 4
};

// Scratch arrays of the kernel.
struct GompperKrollScratch {
  std::vector<double> half_T, us, corner_grad, m;
};

// The energy E = kB sum_i |S_i|^2 / D_i (eqs. (A.1)-(A.2)), optionally its gradient and the sums.
//
// Differentiating E~_i = 2 |S_i|^2 / D_i with u_i = 4 S_i / D_i and s_i = 2 |S_i|^2 / D_i^2:
//
//   dE~_i = u_i . dS_i - s_i dD_i
//         = sum_j dT_ij [u_i . d_ij - s_i l_ij^2] + sum_j T_ij (u_i - 2 s_i d_ij) . (dx_i - dx_j),
//
// d_ij = x_i - x_j: the terms of (A.4)-(A.5). An edge e = (a, b) appears in the rings of a and b,
// so with du = u_a - u_b, ss = s_a + s_b, d = x_a - x_b:
//
//   sum_i dE~_i = sum_e c_e dT_e + sum_e g_e . (dx_a - dx_b),
//   c_e = du . d - ss |d|^2,   g_e = T_e (du - 2 ss d).
//
// c_e is symmetric in a, b and g_e antisymmetric, so vertex i collects
// sum_j T_ij (u_i - u_j - 2 (s_i + s_j) d_ij) from its ring without bookkeeping of edge directions.
// T_e is the sum of the cotangents of the two corners opposite e (eq. (A.7)), so the first sum is
// a sum over faces and corners k of c_{e(k)} d cot_k: the face-wise form of (A.8)-(A.9). For
// corner k with u = p_{k+1} - p_k, w = p_{k+2} - p_k, A2 = |u x w| (twice the face area), face
// normal n and cot_k = u . w / A2:
//
//   d cot_k / d p_{k+1} = (w - cot_k (w x n)) / A2,   d cot_k / d p_{k+2} = (u - cot_k (n x u)) / A2,
//   d cot_k / d p_k = -(sum of the two).
//
// Every loop writes only to its own element (faces: their corners and their edge slots;
// vertices: themselves, gathering over their one-ring), so each runs in parallel without write
// conflicts.
//
// With c0 and ADE (docs/conventions.md §5), E = 2 kB sum_i (H_i - c0)^2 A_i + E_ADE(M) with the
// signed H_i = sigma_i |S_i| / (4 A_i), sigma_i = sign(S_i . N_i), N_i the area-weighted vertex
// normal (sum of the ring's face normals), and M = sum_i H_i A_i = sum_i sigma_i |S_i| / 4. sigma is
// piecewise constant, so no derivative of a normal appears (Bian et al. 2020 use S_i . n_i with a
// normal they do not differentiate; sigma |S_i| is the same where S_i is parallel to n_i):
//   E~_i = 2 |S_i|^2 / D_i - 2 c0 sigma_i |S_i| + c0^2 D_i / 2,   E = kB/2 sum_i E~_i + E_ADE,
// so only u_i and s_i of the derivation above change:
//   u_i = 4 S_i / D_i + (lambda / (2 kB) - 2 c0) sigma_i S_i / |S_i|,   s_i = 2 |S_i|^2 / D_i^2 - c0^2 / 2,
// lambda / kB = alpha pi (M - M0) / A. Plain parameters keep the expressions above.
double gk_kernel(const Topology& t, const Points& x, const BendingParameters& p, Points* force, VertexSums* sums,
                 GompperKrollScratch& ws) {
  const double kappa_b = p.kappa_b;
  const bool plain = p.plain();
  const int nf = t.num_faces(), nv = t.num_vertices(), ne = t.num_edges();
  const Faces& F = t.faces();
  const Faces& FE = t.face_edges();
  const IndexPairs& EF = t.edge_faces();
  const auto& roff = t.ring_offsets();
  const auto& rverts = t.ring_vertices();
  const auto& redges = t.ring_edges();
  const auto& rfaces = t.ring_faces();
  const auto& rcorners = t.ring_corners();

  // half_T[2e + s] = cotangent of the corner opposite e in edge_faces(e, s); T_e is their sum.
  ws.half_T.resize(2 * static_cast<size_t>(ne));
  // Per vertex: u_i (3) and s_i of the derivation above.
  ws.us.resize(4 * static_cast<size_t>(nv));
  // Per face and corner: the gradient of sum_k c_{e(k)} cot_k with respect to that corner.
  if (force) {
    ws.corner_grad.resize(9 * static_cast<size_t>(nf));
    force->resize(nv, 3);
  }
  if (sums) {
    sums->S.resize(nv, 3);
    sums->D.resize(nv);
  }
  // With c0 / ADE: m_i (nv), S_i (3 nv), D_i (nv).
  if (!plain) ws.m.resize(5 * static_cast<size_t>(nv));
  if (sums && !plain) sums->m.resize(nv);
  double* mh = ws.m.data();
  double energy_terms = 0;
  double* half_T = ws.half_T.data();
  double* us = ws.us.data();
  double* corner_grad = ws.corner_grad.data();
  double energy = 0;

#pragma omp parallel if (nf >= kBendingParallelMinFaces)
  {
#pragma omp for schedule(static)
    for (int f = 0; f < nf; ++f) {
      const Vec3 p[3] = {row(x, F(f, 0)), row(x, F(f, 1)), row(x, F(f, 2))};
      const double inv_A2 = 1.0 / (p[1] - p[0]).cross(p[2] - p[0]).norm();
      for (int k = 0; k < 3; ++k) {
        const int e = FE(f, k);
        const int slot = EF(e, 0) == f ? 0 : 1;
        half_T[2 * e + slot] = (p[(k + 1) % 3] - p[k]).dot(p[(k + 2) % 3] - p[k]) * inv_A2;
      }
    }
#pragma omp for schedule(static) reduction(+ : energy)
    for (int i = 0; i < nv; ++i) {
      const Vec3 xi = row(x, i);
      Vec3 S = Vec3::Zero();
      double D = 0;
      for (int r = roff[i]; r < roff[i + 1]; ++r) {
        const int e = redges[r];
        const double T = half_T[2 * e] + half_T[2 * e + 1];
        const Vec3 d = xi - row(x, rverts[r]);
        S += T * d;
        D += T * d.squaredNorm();
      }
      const double S2 = S.squaredNorm();
      energy += S2 / D;
      const double inv_D = 1.0 / D;
      us[4 * i] = 4.0 * inv_D * S[0];
      us[4 * i + 1] = 4.0 * inv_D * S[1];
      us[4 * i + 2] = 4.0 * inv_D * S[2];
      us[4 * i + 3] = 2.0 * S2 * inv_D * inv_D;
      if (sums) {
        sums->S.row(i) = S.transpose();
        sums->D[i] = D;
      }
      if (!plain) {
        Vec3 N = Vec3::Zero();  // area-weighted normal (times 2)
        for (int r = roff[i]; r < roff[i + 1]; ++r) {
          const int f = rfaces[r];
          const Vec3 p0 = row(x, F(f, 0));
          N += (row(x, F(f, 1)) - p0).cross(row(x, F(f, 2)) - p0);
        }
        const double sn = std::sqrt(S2);
        mh[i] = (S.dot(N) < 0 ? -0.25 : 0.25) * sn;
        for (int c = 0; c < 3; ++c) mh[nv + 3 * i + c] = S[c];
        mh[4 * nv + i] = D;
      }
    }
    if (!plain) {
#pragma omp single
      {
        double mtot = 0, et = 0;
        for (int i = 0; i < nv; ++i) mtot += mh[i];
        const double lk = p.has_ade() ? p.ade_alpha * M_PI * (mtot - p.ade_m0()) / p.ade_area : 0.0;
        for (int i = 0; i < nv; ++i) {
          const double D = mh[4 * nv + i];
          const Vec3 S(mh[nv + 3 * i], mh[nv + 3 * i + 1], mh[nv + 3 * i + 2]);
          const double sn = S.norm();
          const double sigma = mh[i] < 0 ? -1.0 : 1.0;
          et += 2.0 * sn * sn / D - 2.0 * p.c0 * sigma * sn + 0.5 * p.c0 * p.c0 * D;
          const double cu = sn > 0 ? (0.5 * lk - 2.0 * p.c0) * sigma / sn : 0.0;
          for (int c = 0; c < 3; ++c) us[4 * i + c] += cu * S[c];
          us[4 * i + 3] -= 0.5 * p.c0 * p.c0;
          if (sums) sums->m[i] = mh[i];
        }
        energy_terms = 0.5 * kappa_b * et + p.ade_energy(mtot);
      }
    }
    if (force) {
#pragma omp for schedule(static)
      for (int f = 0; f < nf; ++f) {
        int v[3];
        Vec3 p[3], u[3];
        double s[3];
        for (int k = 0; k < 3; ++k) {
          v[k] = F(f, k);
          p[k] = row(x, v[k]);
          u[k] = Vec3(us[4 * v[k]], us[4 * v[k] + 1], us[4 * v[k] + 2]);
          s[k] = us[4 * v[k] + 3];
        }
        // E[k] = edge opposite corner k, from corner k+1 to corner k+2; R[k] = n x E[k]. With
        // a = p_{k+1} - p_k = E[k+2] and w = p_{k+2} - p_k = -E[k+1] the derivatives above read
        //   d cot_k / d p_{k+1} = -(E[k+1] + cot_k R[k+1]) / A2,
        //   d cot_k / d p_{k+2} = (E[k+2] - cot_k R[k+2]) / A2,
        // and cot_k = -E[k+2] . E[k+1] / A2.
        const Vec3 E[3] = {p[2] - p[1], p[0] - p[2], p[1] - p[0]};
        const Vec3 m = E[2].cross(-E[1]);
        const double inv_A2 = 1.0 / m.norm();
        const Vec3 n = m * inv_A2;
        const Vec3 R[3] = {n.cross(E[0]), n.cross(E[1]), n.cross(E[2])};
        Vec3 grad[3] = {Vec3::Zero(), Vec3::Zero(), Vec3::Zero()};
        for (int k = 0; k < 3; ++k) {
          const int k1 = (k + 1) % 3, k2 = (k + 2) % 3;
          const double cot = -E[k2].dot(E[k1]) * inv_A2;
          // c_e of the edge (k1, k2) opposite corner k (d = p_{k1} - p_{k2} = -E[k]), over A2.
          const double c = (-(u[k1] - u[k2]).dot(E[k]) - (s[k1] + s[k2]) * E[k].squaredNorm()) * inv_A2;
          const Vec3 g1 = -c * (E[k1] + cot * R[k1]);
          const Vec3 g2 = c * (E[k2] - cot * R[k2]);
          grad[k1] += g1;
          grad[k2] += g2;
          grad[k] -= g1 + g2;
        }
        for (int k = 0; k < 3; ++k)
          for (int c = 0; c < 3; ++c) corner_grad[9 * f + 3 * k + c] = grad[k][c];
      }
      const double scale = -0.5 * kappa_b;  // F = -dE/dx, E = kB/2 sum_i E~_i (eq. (A.1))
#pragma omp for schedule(static)
      for (int i = 0; i < nv; ++i) {
        const Vec3 xi = row(x, i);
        const Vec3 ui(us[4 * i], us[4 * i + 1], us[4 * i + 2]);
        const double si = us[4 * i + 3];
        Vec3 g = Vec3::Zero();
        for (int r = roff[i]; r < roff[i + 1]; ++r) {
          const int f = rfaces[r], k = rcorners[r], e = redges[r], j = rverts[r];
          const double* cg = &corner_grad[9 * f + 3 * k];
          const double T = half_T[2 * e] + half_T[2 * e + 1];
          const Vec3 uj(us[4 * j], us[4 * j + 1], us[4 * j + 2]);
          g += Vec3(cg[0], cg[1], cg[2]) + T * (ui - uj - 2.0 * (si + us[4 * j + 3]) * (xi - row(x, j)));
        }
        force->row(i) = (scale * g).transpose();
      }
    }
  }
  return plain ? kappa_b * energy : energy_terms;
}

}  // namespace

// The kernel's scratch, its sums and compute()'s geometry, kept by the method instance and reused
// from call to call, so a time loop does not allocate (and page in) fresh memory at every step
// (method_workspace.hpp).
struct GompperKroll::Workspace {
  GompperKrollScratch kernel;
  VertexSums sums;
  MeshGeometry geometry;
};

GompperKroll::GompperKroll() = default;
GompperKroll::~GompperKroll() = default;

std::unique_ptr<BendingMethod> GompperKroll::create(const MethodOptions& options) {
  resolve_method_options(info(), options);  // B takes no options: refuses any
  return std::make_unique<GompperKroll>();
}

MethodInfo GompperKroll::info() {
  MethodInfo m{"B", "Gompper-Kroll: exact gradient of the discrete Helfrich energy, eqs. (A.1)-(A.2)",
                {}, {}, &GompperKroll::create};
  m.capabilities.has_energy = true;
  m.capabilities.defines_lapH = false;
  return m;
}

void GompperKroll::forces(const Topology& t, const Points& x, double kappa_b, Points& force) const {
  gk_kernel(t, x, BendingParameters(kappa_b), &force, nullptr, workspace_.acquire()->kernel);
}

std::optional<double> GompperKroll::energy(const Topology& t, const Points& x, double kappa_b) const {
  return gk_kernel(t, x, BendingParameters(kappa_b), nullptr, nullptr, workspace_.acquire()->kernel);
}

BendingResult GompperKroll::compute(const Topology& t, const Points& x, double kappa_b) const {
  return compute_terms(t, x, BendingParameters(kappa_b));
}

void GompperKroll::compute_into(const Topology& t, const Points& x, double kappa_b, BendingResult& out) const {
  compute_terms_into(t, x, BendingParameters(kappa_b), out);
}

void GompperKroll::forces_terms(const Topology& t, const Points& x, const BendingParameters& p, Points& force) const {
  gk_kernel(t, x, p, &force, nullptr, workspace_.acquire()->kernel);
}

std::optional<double> GompperKroll::energy_terms(const Topology& t, const Points& x, const BendingParameters& p) const {
  return gk_kernel(t, x, p, nullptr, nullptr, workspace_.acquire()->kernel);
}

BendingResult GompperKroll::compute_terms(const Topology& t, const Points& x, const BendingParameters& p) const {
  BendingResult r;
  compute_terms_into(t, x, p, r);
  return r;
}

void GompperKroll::compute_terms_into(const Topology& t, const Points& x, const BendingParameters& p,
                                      BendingResult& r) const {
  const int nv = t.num_vertices();
  const auto ws = workspace_.acquire();
  VertexSums& sums = ws->sums;
  r.energy = gk_kernel(t, x, p, &r.force, &sums, ws->kernel);
  MeshGeometry& g = ws->geometry;
  MeshGeometry::compute(t, x, g);
  r.H.resize(nv);
  r.force_density.resize(nv, 3);
  for (int i = 0; i < nv; ++i) {
    // |S_i| / (4 A_i) with 4 A_i = D_i / 2 (eq. (9)); the sign of S_i . n_i is that of
    // -1/2 (Lap x)_i . n_i, because S_i = -2 A_i (Lap x)_i with the div-grad Laplacian.
    const double magnitude = 2.0 * sums.S.row(i).norm() / sums.D[i];
    if (p.plain())
      r.H[i] = sums.S.row(i).dot(g.normal_mwa.row(i)) < 0 ? -magnitude : magnitude;
    else  // the sign the energy uses (area-weighted normal, see gk_kernel)
      r.H[i] = sums.m[i] < 0 ? -magnitude : magnitude;
    r.force_density.row(i) = r.force.row(i) / g.mixed_area[i];  // eq. (14)
  }
  // The geometry's arrays change places with the result's (no copy; next call they are reused).
  r.area.swap(g.mixed_area);
  r.normal.swap(g.normal_mwa);
  r.K.swap(g.gaussian_curvature);
  r.lapH.setConstant(nv, std::numeric_limits<double>::quiet_NaN());
}

}  // namespace bendlab
