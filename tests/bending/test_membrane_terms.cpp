// Spontaneous curvature c0 and area-difference elasticity (ADE): the continuum force law of
// docs/conventions.md §5 against the continuum energy, without any mesh; the energy methods'
// forces against central differences of their discrete energies; plain parameters taking the
// paper's code path; refusals.
#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <cstdio>
#include <numbers>
#include <vector>

#include "bendlab/bending/bending_parameters.hpp"
#include "bendlab/bending/loop_shell.hpp"
#include "bendlab/bending/method_registry.hpp"
#include "bendlab/geometry/measures.hpp"
#include "bendlab/mesh/generators.hpp"
#include "bendlab/surfaces/surface_of_revolution.hpp"
#include "energy_test_support.hpp"

namespace bendlab {
namespace {

constexpr double kPi = std::numbers::pi;

// Gauss-Legendre nodes and weights on [a, b] (Newton on P_n).
void gauss_legendre(int n, double a, double b, std::vector<double>& t, std::vector<double>& w) {
  t.resize(n);
  w.resize(n);
  for (int i = 0; i < n; ++i) {
    double x = std::cos(kPi * (i + 0.75) / (n + 0.5)), dp = 0;
    for (int it = 0; it < 100; ++it) {
      double p0 = 1, p1 = x;
      for (int k = 2; k <= n; ++k) {
        const double p2 = ((2 * k - 1) * x * p1 - (k - 1) * p0) / k;
        p0 = p1, p1 = p2;
      }
      dp = n * (x * p1 - p0) / (x * x - 1);
      const double dx = p1 / dp;
      x -= dx;
      if (std::abs(dx) < 1e-16) break;
    }
    t[i] = 0.5 * (a + b) + 0.5 * (b - a) * x;
    w[i] = (b - a) / ((1 - x * x) * dp * dp);
  }
}

// The continuum energy E = 2 kB ∫ (H - c0)^2 dA + E_ADE(M) of the surface of revolution whose
// meridian is x(t) + eps psi(t) n(t), t in [0, pi]. The meridian, extended to t in [0, 2 pi) by
// r(2 pi - t) = -r(t), z(2 pi - t) = z(t), is a smooth periodic curve (psi even about 0 and pi):
// it is sampled at N points, differentiated spectrally and integrated by Gauss-Legendre in t.
class ContinuumEnergy {
 public:
  ContinuumEnergy(const SurfaceOfRevolution& s, double (*psi)(double), int samples = 256, int nodes = 200)
      : s_(s), psi_(psi), n_(samples) {
    gauss_legendre(nodes, 0, kPi, t_, w_);
  }
  struct Sums {
    double E, M;
  };
  // E(eps) and M(eps).
  Sums at(double eps, const BendingParameters& p) const {
    // Samples of the perturbed meridian and their Fourier coefficients.
    std::vector<double> r(n_), z(n_);
    for (int j = 0; j < n_; ++j) {
      const double t = 2 * kPi * j / n_;
      const bool mirror = t > kPi;
      const MeridianValues m = s_.meridian(mirror ? 2 * kPi - t : t);
      const double sg = mirror ? -1 : 1;
      r[j] = sg * (m.r + eps * psi_(t) * m.n_r);
      z[j] = m.z + eps * psi_(t) * m.n_z;
    }
    std::vector<std::complex<double>> cr(n_), cz(n_);
    for (int k = 0; k < n_; ++k) {
      std::complex<double> ar = 0, az = 0;
      for (int j = 0; j < n_; ++j) {
        const std::complex<double> e = std::polar(1.0 / n_, -2 * kPi * double(k) * j / n_);
        ar += r[j] * e, az += z[j] * e;
      }
      cr[k] = ar, cz[k] = az;
    }
    double E = 0, M = 0;
    for (size_t q = 0; q < t_.size(); ++q) {
      double v[2][3] = {};  // r, z and their first two derivatives
      for (int k = 0; k < n_; ++k) {
        const int m = k <= n_ / 2 ? k : k - n_;
        if (2 * std::abs(m) == n_) continue;  // the Nyquist mode of a real signal: drop
        const std::complex<double> e = std::polar(1.0, m * t_[q]), im(0, m);
        const std::complex<double> c[2] = {cr[k], cz[k]};
        for (int a = 0; a < 2; ++a) {
          v[a][0] += (c[a] * e).real();
          v[a][1] += (c[a] * e * im).real();
          v[a][2] += (c[a] * e * im * im).real();
        }
      }
      const double rr = v[0][0], r1 = v[0][1], r2 = v[0][2], z1 = v[1][1], z2 = v[1][2];
      const double sp = std::hypot(r1, z1);
      const double km = -(r1 * z2 - z1 * r2) / (sp * sp * sp), kp = -z1 / (rr * sp);
      const double H = 0.5 * (km + kp), dA = 2 * kPi * rr * sp * w_[q];
      E += 2 * p.kappa_b * (H - p.c0) * (H - p.c0) * dA;
      M += H * dA;
    }
    return {E + p.ade_energy(M), M};
  }
  // -∫ f_n psi dA with f_n the force law at the unperturbed surface (exact H, K, Lap H).
  double work(const BendingParameters& p) const {
    const double lambda = p.ade_lambda(at(0, p).M);
    double s = 0;
    for (size_t q = 0; q < t_.size(); ++q) {
      const MeridianValues m = s_.meridian(t_[q]);
      const double fn = membrane_normal_force(m.H, m.K, m.lapH, p.c0, p.kappa_b, lambda);
      s -= fn * psi_(t_[q]) * 2 * kPi * m.r * m.ds_dt * w_[q];
    }
    return s;
  }

 private:
  const SurfaceOfRevolution& s_;
  double (*psi_)(double);
  int n_;
  std::vector<double> t_, w_;
};

double psi_smooth(double t) { return 0.3 + std::cos(t) + 0.5 * std::cos(2 * t) - 0.2 * std::cos(3 * t); }

SurfaceOfRevolution rbc_surface() {
  return SurfaceOfRevolution("rbc", 1.0, {0.5 * kRbcC0, 0.5 * kRbcC1, 0.5 * kRbcC2},
                             SurfaceOfRevolution::SphereMap::RbcHeight);
}

BendingParameters params(double kb, double c0, double alpha = 0, double area = 0) {
  BendingParameters p(kb);
  p.c0 = c0;
  p.ade_alpha = alpha;
  p.ade_d = 0.02;
  p.ade_da0 = 0.1;
  p.ade_area = area;
  return p;
}

// The acceptance check: dE/deps by a central difference of the quadrature energy equals
// -∫ f . (psi n) dA to 1e-6 relative, on the RBC of eq. (15), with c0 of both signs and ADE.
TEST(MembraneTerms, ContinuumForceLawIsMinusTheEnergyDerivativeOnTheRbc) {
  const SurfaceOfRevolution rbc = rbc_surface();
  const ContinuumEnergy ce(rbc, psi_smooth);
  const double area = 2 * kPi * 4.0;  // any fixed A: a parameter of the energy
  for (const BendingParameters& p : {params(1.3, 0.0), params(1.3, 1.0), params(1.3, -1.0),
                                      params(0.7, 0.0, 3.0, area), params(0.7, -0.8, 3.0, area)}) {
    const double h = 1e-5;
    const double dE = (ce.at(h, p).E - ce.at(-h, p).E) / (2 * h);
    const double w = ce.work(p);
    EXPECT_NEAR(dE, w, 1e-6 * std::abs(w)) << p.describe();
    std::printf("[continuum RBC] %s: dE/deps %.12g, -int f psi dA %.12g, relative difference %.2e\n",
                p.describe().c_str(), dE, w, std::abs(dE - w) / std::abs(w));
  }
}

TEST(MembraneTerms, SphereClosedForms) {
  // f_n = 4 kB c0 (1/R - c0) / R (c0 alone), minus lambda K with ADE: dE/dR of
  // E = 8 pi kB (1 - c0 R)^2 + alpha pi kB (4 pi R - M0)^2 / (2 A) is -4 pi R^2 f_n.
  const double R = 1.3, kb = 0.9;
  for (double c0 : {0.5, -1.0, 1.0 / R}) {
    const BendingParameters p = params(kb, c0, 2.0, 11.0);
    const double M = 4 * kPi * R;
    const double fn = membrane_normal_force(1 / R, 1 / (R * R), 0, c0, kb, p.ade_lambda(M));
    const double closed = 4 * kb * c0 * (1 / R - c0) / R - p.ade_lambda(M) / (R * R);
    EXPECT_NEAR(fn, closed, 1e-14);
    const double dEdR = -16 * kPi * kb * c0 * (1 - c0 * R) + p.ade_alpha * kPi * kb * (M - p.ade_m0()) * 4 * kPi / 11.0;
    EXPECT_NEAR(-4 * kPi * R * R * fn, dEdR, 1e-12 * std::abs(dEdR) + 1e-13);
  }
  // The mesh-free check on a sphere too (a sphere of radius R: A = R, Z = R).
  const SurfaceOfRevolution sphere("sphere", R, {R}, SurfaceOfRevolution::SphereMap::Scale);
  const ContinuumEnergy ce(sphere, psi_smooth, 64, 64);
  const BendingParameters p = params(kb, 0.6, 2.0, 11.0);
  const double h = 1e-5;
  EXPECT_NEAR((ce.at(h, p).E - ce.at(-h, p).E) / (2 * h), ce.work(p), 1e-7 * std::abs(ce.work(p)));
}

// Energy methods: F = -dE/dx with c0 and ADE, on a perturbed sphere and on an irregular RBC mesh.
TEST(MembraneTerms, EnergyMethodsForceIsMinusGradient) {
  const TriMesh sphere = test_support::perturbed_sphere(1, 0.1);
  const TriMesh rbc = test_support::rivara_rbc();
  for (const char* name : {"B", "J"}) {
    const auto method = make_bending_method(name);
    for (const TriMesh* mesh : {&sphere, &rbc}) {
      const double area = surface_area(mesh->topology(), mesh->positions());
      for (const BendingParameters& p : {params(1.0, -1.5, 4.0, area)}) {  // c0 and ADE together
        // The support's helper differentiates energy(.., 1.0): wrap the parameters in a method.
        struct WithTerms : BendingMethod {
          const BendingMethod& m;
          BendingParameters p;
          WithTerms(const BendingMethod& m, BendingParameters p) : m(m), p(p) {}
          std::string name() const override { return m.name(); }
          BendingResult compute(const Topology& t, const Points& x, double) const override {
            return m.compute(t, x, p);
          }
          void forces(const Topology& t, const Points& x, double, Points& f) const override { m.forces(t, x, p, f); }
          std::optional<double> energy(const Topology& t, const Points& x, double) const override {
            return m.energy(t, x, p);
          }
        } wrapped(*method, p);
        SCOPED_TRACE(std::string(name) + " " + p.describe());
        test_support::expect_force_is_minus_gradient(wrapped, *mesh, 1e-6);
        // compute() agrees with forces() and its energy with energy().
        const BendingResult r = method->compute(mesh->topology(), mesh->positions(), p);
        Points f;
        method->forces(mesh->topology(), mesh->positions(), p, f);
        EXPECT_LT((r.force - f).norm(), 1e-12 * f.norm());
        EXPECT_NEAR(*r.energy, *method->energy(mesh->topology(), mesh->positions(), p), 1e-12 * std::abs(*r.energy));
      }
    }
  }
}

TEST(MembraneTerms, LoopShellControlGradientMatchesCentralDifferences) {
  const TriMesh m = sphere_mesh(MeshFamily::MT1, 1);  // 80 triangles
  const Points x = make_rbc()->map_from_unit_sphere(m.positions());
  const LoopShellMethod s(LoopShellMethod::Control::Nodes, 3, LoopShellMethod::HMode::Limit);
  const BendingParameters p = params(1.0, -1.2, 4.0, 12.0);
  Points grad;
  s.control_energy(m.topology(), x, p, &grad);
  const double h = 1e-6, scale = grad.cwiseAbs().maxCoeff();
  for (int i : {0, 7, 23, 40}) {
    for (int k = 0; k < 3; ++k) {
      Points xp = x, xm = x;
      xp(i, k) += h, xm(i, k) -= h;
      const double fd = (s.control_energy(m.topology(), xp, p) - s.control_energy(m.topology(), xm, p)) / (2 * h);
      EXPECT_NEAR(grad(i, k), fd, 1e-6 * scale) << i << " " << k;
    }
  }
}

// The discrete integrals of H: J's sum_e l_e theta_e / 2 and B's sum sigma |S| / 4 tend to
// M = 4 pi R on a sphere, so the ADE term of the energy tends to its continuum value there.
TEST(MembraneTerms, SphereEnergiesTendToTheContinuum) {
  const TriMesh m = sphere_mesh(MeshFamily::MT1, 3);  // 1280 triangles, R = 1
  const double c0 = 0.4;
  BendingParameters p = params(1.0, c0, 2.0, 4 * kPi);
  const double exact = 8 * kPi * (1 - c0) * (1 - c0) + p.ade_energy(4 * kPi);
  for (const char* name : {"B", "J", "S"}) {
    const double e = *make_bending_method(name)->energy(m.topology(), m.positions(), p);
    EXPECT_NEAR(e / exact, 1.0, 0.02) << name;
  }
}

// The variational methods on a sphere: the c0 part of f_n, f_n(c0) - f_n(0) (which does not
// carry the methods' error of Lap H), tends to 4 kB c0 (1/R - c0)/R.
TEST(MembraneTerms, VariationalMethodsOnASphere) {
  const TriMesh m = sphere_mesh(MeshFamily::MT1, 2);
  const double R = 1.0, c0 = -0.7;
  const double closed = 4 * c0 * (1 / R - c0) / R;
  for (const char* name : {"C", "D", "E", "ED", "M"}) {
    const auto method = make_bending_method(name);
    const BendingResult r = method->compute(m.topology(), m.positions(), params(1.0, c0));
    const BendingResult r0 = method->compute(m.topology(), m.positions(), 1.0);
    double worst = 0;
    for (int i = 0; i < m.num_vertices(); ++i)
      worst = std::max(worst, std::abs((r.force_density - r0.force_density).row(i).dot(m.positions().row(i)) - closed));
    EXPECT_LT(worst, 0.1 * std::abs(closed)) << name;  // a wrong sign or factor is off by 25% or more
  }
}

TEST(MembraneTerms, PlainParametersTakeThePaperPath) {
  const TriMesh m = sphere_mesh(MeshFamily::MT1, 2);
  const Points x = make_rbc()->map_from_unit_sphere(m.positions());
  for (const std::string& name : bending_method_names()) {
    const auto method = make_bending_method(name);
    const BendingResult a = method->compute(m.topology(), x, 1.7);
    const BendingResult b = method->compute(m.topology(), x, BendingParameters(1.7));
    EXPECT_TRUE(a.force == b.force) << name;
    EXPECT_TRUE(a.force_density == b.force_density) << name;
  }
}

TEST(MembraneTerms, RefusesBadParametersAndMethodA) {
  const TriMesh m = sphere_mesh(MeshFamily::MT1, 1);
  const auto a = make_bending_method("A");
  EXPECT_THROW(a->compute(m.topology(), m.positions(), params(1.0, 0.5)), Error);
  EXPECT_NO_THROW(a->compute(m.topology(), m.positions(), params(1.0, 0.0)));
  const auto c = make_bending_method("C");
  EXPECT_THROW(c->check_parameters(params(1.0, std::nan(""))), Error);
  EXPECT_THROW(c->check_parameters(params(1.0, 0.0, -1.0, 1.0)), Error);
  EXPECT_THROW(c->check_parameters(params(1.0, 0.0, 1.0, 0.0)), Error);  // ADE without an area
  BendingParameters p = params(1.0, 0.0, 1.0, 1.0);
  p.ade_d = -0.1;
  EXPECT_THROW(c->check_parameters(p), Error);
  try {
    a->check_parameters(params(1.0, 0.5));
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("method A"), std::string::npos);
  }
}

TEST(MembraneTerms, AnOverflowingAdeTermIsRefusedNamingIt) {
  // d = 1e-300 with dA0 = 0.1 puts M0 = dA0 / (2 d) at 5e298: the term alpha pi kB (M - M0)^2 /
  // (2 A) is no number. Refused as the ADE term, not found later as a failing run.
  BendingParameters p = params(1.0, 0.0, 1.0, 12.0);
  p.ade_d = 1e-300;
  try {
    p.validate();
    ADD_FAILURE() << "accepted d = 1e-300";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("ADE term"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("d = 1e-300"), std::string::npos) << e.what();
  }
  p.ade_alpha = 1e308;  // the coefficient alone overflows
  p.ade_d = 0.02;
  p.ade_area = 1e-10;
  EXPECT_THROW(p.validate(), Error);
  p = params(1.0, 0.0, 1.0, 12.0);
  p.ade_d = 1e-300;
  p.ade_da0 = 0;  // M0 = 0: a tiny d alone is harmless
  EXPECT_NO_THROW(p.validate());
}

}  // namespace
}  // namespace bendlab
