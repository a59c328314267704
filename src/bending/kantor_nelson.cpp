#include "bendlab/bending/kantor_nelson.hpp"

#include <cmath>
#include <limits>
#include <vector>

#include "bendlab/geometry/mesh_geometry.hpp"

namespace bendlab {

namespace {

// theta / sin(theta) for theta in [0, pi), from s = sin(theta) >= 0 and theta. Below the
// threshold the series 1 + theta^2/6 (next term 7 theta^4/360 < 1e-17) replaces the quotient,
// so a flat edge (s = theta = 0) gives exactly 1 (footnote 1 of the paper).
inline double theta_over_sin(double theta, double s) {
  return theta < 1e-4 ? 1.0 + theta * theta / 6.0 : theta / s;
}

}  // namespace

// Scratch arrays of the force kernel and the geometry of compute(), kept by the method instance
// and reused from call to call, so a time loop does not allocate (and page in) fresh memory at
// every step (method_workspace.hpp).
struct KantorNelson::Workspace {
  std::vector<double> normal, inv_len, dEdc, W;
  MeshGeometry geometry;
};

KantorNelson::KantorNelson(bool small_angle) : small_angle_(small_angle) {}
KantorNelson::~KantorNelson() = default;

std::unique_ptr<BendingMethod> KantorNelson::create(const MethodOptions& options) {
  const MethodOptions o = resolve_method_options(info(), options);
  return std::make_unique<KantorNelson>(option_bool(o, "small_angle"));
}

std::string KantorNelson::membrane_terms_refusal() const {
  // A preferred dihedral angle theta0 (E_e = 2 kB~ (1 - cos(theta - theta0))) is the usual way to
  // give eq. (6) a spontaneous curvature, but theta0 = f(c0, edge length) only has a continuum
  // limit on a tiling of equal equilateral triangles, and eq. (6) itself converges to a
  // triangulation-dependent energy (header); there is no discrete integral of H to build ADE on.
  return "Kantor-Nelson's dihedral energy has no mesh-independent preferred angle for a spontaneous "
         "curvature and no integral of H for ADE";
}

MethodInfo KantorNelson::info() {
  MethodInfo m{"A", "Kantor-Nelson: gradient of the dihedral-angle energy, eq. (6)",
                {bool_option("small_angle", false, "small-angle form theta^2/2 of 1 - cos(theta)")}, {},
                &KantorNelson::create};
  m.capabilities.has_energy = true;
  m.capabilities.defines_H = false;
  m.capabilities.defines_K = false;
  m.capabilities.defines_lapH = false;
  return m;
}

// With c = n_f . n_g for the two faces f, g of an edge, eq. (6) is E_e = 2 kB~ (1 - c) and its
// small-angle form E_e = kB~ theta^2, theta = acos(c). Writing the unnormalised face normal
// m_f = (p1 - p0) x (p2 - p0), n_f = m_f / |m_f|, one has dn_f = (I - n_f n_f^T) dm_f / |m_f|, so
//
//   dc = W_fg . dm_f + W_gf . dm_g,   W_fg = (n_g - c n_f) / |m_f|,
//
// with no division by sin(theta). For the small-angle form dE_e/dc = -2 kB~ theta / sin(theta),
// which tends to -2 kB~ at a flat edge. Collecting per face W_f = sum over its three edges of
// dE_e/dc W_fg, and using d(W . m_f)/dp_k = (p_{k+1} - p_{k+2}) x W for corner k, the force is
//
//   F_i = - sum_{faces f at i, i = corner k} (p_{k+1} - p_{k+2}) x W_f.
//
// Each loop writes only to its own element (faces, edges, vertices) and gathers from its
// neighbours, so the loops run in parallel without write conflicts.
double KantorNelson::energy_and_forces(const Topology& t, const Points& x, double kappa_b, Points& force,
                                       Workspace& ws) const {
  const int nf = t.num_faces(), nv = t.num_vertices(), ne = t.num_edges();
  const Faces& F = t.faces();
  const Faces& FE = t.face_edges();
  const IndexPairs& EF = t.edge_faces();
  const auto& roff = t.ring_offsets();
  const auto& rfaces = t.ring_faces();
  const auto& rcorners = t.ring_corners();
  const double kt = std::sqrt(3.0) * kappa_b;  // kB~ of eq. (6)
  const bool small = small_angle_;

  ws.normal.resize(3 * static_cast<size_t>(nf));  // unit face normals n_f
  ws.inv_len.resize(nf);                          // 1 / |m_f|
  ws.dEdc.resize(ne);                             // dE_e / dc per edge
  ws.W.resize(3 * static_cast<size_t>(nf));       // W_f
  double* normal = ws.normal.data();
  double* inv_len = ws.inv_len.data();
  double* dEdc = ws.dEdc.data();
  double* W = ws.W.data();
  force.resize(nv, 3);
  auto nrm = [normal](int f) { return Vec3(normal[3 * f], normal[3 * f + 1], normal[3 * f + 2]); };
  double energy = 0;

#pragma omp parallel if (nf >= kBendingParallelMinFaces)
  {
#pragma omp for schedule(static)
    for (int f = 0; f < nf; ++f) {
      const Vec3 p0 = row(x, F(f, 0)), p1 = row(x, F(f, 1)), p2 = row(x, F(f, 2));
      const Vec3 m = (p1 - p0).cross(p2 - p0);
      const double len = m.norm();
      inv_len[f] = 1.0 / len;
      for (int c = 0; c < 3; ++c) normal[3 * f + c] = m[c] / len;
    }
#pragma omp for schedule(static) reduction(+ : energy)
    for (int e = 0; e < ne; ++e) {
      const Vec3 n0 = nrm(EF(e, 0)), n1 = nrm(EF(e, 1));
      if (small) {
        const double s = n0.cross(n1).norm();
        const double theta = std::atan2(s, n0.dot(n1));
        energy += kt * theta * theta;
        dEdc[e] = -2.0 * kt * theta_over_sin(theta, s);
      } else {
        energy += kt * (n0 - n1).squaredNorm();  // = 2 kB~ (1 - c), without cancellation near c = 1
        dEdc[e] = -2.0 * kt;
      }
    }
#pragma omp for schedule(static)
    for (int f = 0; f < nf; ++f) {
      const Vec3 nf_ = nrm(f);
      Vec3 w = Vec3::Zero();
      for (int k = 0; k < 3; ++k) {
        const int e = FE(f, k);
        const Vec3 ng = nrm(EF(e, 0) == f ? EF(e, 1) : EF(e, 0));
        w += dEdc[e] * (ng - nf_.dot(ng) * nf_);
      }
      w *= inv_len[f];
      for (int c = 0; c < 3; ++c) W[3 * f + c] = w[c];
    }
#pragma omp for schedule(static)
    for (int i = 0; i < nv; ++i) {
      Vec3 s = Vec3::Zero();
      for (int r = roff[i]; r < roff[i + 1]; ++r) {
        const int f = rfaces[r], k = rcorners[r];
        const Vec3 w(W[3 * f], W[3 * f + 1], W[3 * f + 2]);
        s += (row(x, F(f, (k + 1) % 3)) - row(x, F(f, (k + 2) % 3))).cross(w);
      }
      force.row(i) = -s.transpose();
    }
  }
  return energy;
}

void KantorNelson::forces(const Topology& t, const Points& x, double kappa_b, Points& force) const {
  energy_and_forces(t, x, kappa_b, force, *workspace_.acquire());
}

std::optional<double> KantorNelson::energy(const Topology& t, const Points& x, double kappa_b) const {
  const int ne = t.num_edges();
  const Faces& F = t.faces();
  const IndexPairs& EF = t.edge_faces();
  const double kt = std::sqrt(3.0) * kappa_b;
  auto unit_normal = [&](int f) {
    const Vec3 p0 = row(x, F(f, 0)), p1 = row(x, F(f, 1)), p2 = row(x, F(f, 2));
    return Vec3((p1 - p0).cross(p2 - p0).normalized());
  };
  double energy = 0;
#pragma omp parallel for schedule(static) reduction(+ : energy) if (t.num_faces() >= kBendingParallelMinFaces)
  for (int e = 0; e < ne; ++e) {
    const Vec3 n0 = unit_normal(EF(e, 0)), n1 = unit_normal(EF(e, 1));
    if (small_angle_) {
      const double theta = std::atan2(n0.cross(n1).norm(), n0.dot(n1));
      energy += kt * theta * theta;
    } else {
      energy += kt * (n0 - n1).squaredNorm();
    }
  }
  return energy;
}

BendingResult KantorNelson::compute(const Topology& t, const Points& x, double kappa_b) const {
  BendingResult r;
  compute_into(t, x, kappa_b, r);
  return r;
}

void KantorNelson::compute_into(const Topology& t, const Points& x, double kappa_b, BendingResult& r) const {
  const int nv = t.num_vertices();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const auto ws = workspace_.acquire();
  r.energy = energy_and_forces(t, x, kappa_b, r.force, *ws);
  MeshGeometry& g = ws->geometry;
  MeshGeometry::compute(t, x, g);
  // The geometry's arrays change places with the result's (no copy; next call they are reused).
  r.area.swap(g.mixed_area);
  r.normal.swap(g.normal_mwa);
  r.force_density.resize(nv, 3);
  for (int i = 0; i < nv; ++i) r.force_density.row(i) = r.force.row(i) / r.area[i];  // eq. (14)
  r.H.setConstant(nv, nan);
  r.K.setConstant(nv, nan);
  r.lapH.setConstant(nv, nan);
}

}  // namespace bendlab
