#include <gtest/gtest.h>

#include <cmath>
#include <thread>

#include "bendlab/elasticity/neo_hookean.hpp"
#include "bendlab/geometry/measures.hpp"
#include "bendlab/geometry/mesh_geometry.hpp"
#include "bendlab/membrane/membrane_model.hpp"
#include "bendlab/mesh/generators.hpp"

using namespace bendlab;

namespace {
// A sheared sphere: stretched and bent, so every force is non-zero.
Points deformed(const TriMesh& m) {
  Points x = m.positions();
  x.col(0) += 0.3 * x.col(2);
  x.col(1) *= 0.9;
  return x;
}

// E_V = k/2 (V - V0)^2, the simplest volume force, to check the hook.
class TestVolumePenalty final : public VolumeForce {
 public:
  explicit TestVolumePenalty(double k) : k_(k) {}
  std::string name() const override { return "test"; }
  std::optional<double> energy(const Topology& t, const Points& x, double v0) const override {
    const double dv = enclosed_volume(t, x) - v0;
    return 0.5 * k_ * dv * dv;
  }
  void add_forces(const Topology& t, const Points& x, double v0, Points& force) const override {
    // dV/dx_i = 1/6 sum_{faces (i, j, k)} x_j x x_k
    Points grad = Points::Zero(x.rows(), 3);
    const Faces& F = t.faces();
    for (int f = 0; f < F.rows(); ++f)
      for (int c = 0; c < 3; ++c)
        grad.row(F(f, c)) += row(x, F(f, (c + 1) % 3)).cross(row(x, F(f, (c + 2) % 3))).transpose() / 6;
    force -= k_ * (enclosed_volume(t, x) - v0) * grad;
  }

 private:
  double k_;
};
}  // namespace

TEST(MembraneModel, ForcesAreTheSumOfTheirParts) {
  const TriMesh m = sphere_mesh(MeshFamily::MT1, 2);
  const Points x = deformed(m);
  MembraneParameters p;
  p.kS = 10;
  p.kB = 0.375;
  p.bending = make_bending_method("C");
  const MembraneModel model(m, p);
  const NeoHookean elastic(m.topology_ptr(), m.positions(), 10);
  Points fe, fb, f;
  elastic.forces(x, fe);
  p.bending->forces(m.topology(), x, 0.375, fb);
  model.forces(x, f);
  EXPECT_EQ(f, Points(fe + fb));
  // f = F / A_mixed (eq. (14)).
  const MembraneForces all = model.evaluate(x);
  const Scalars area = MeshGeometry::compute(m.topology(), x).mixed_area;
  EXPECT_EQ(all.force, f);
  EXPECT_EQ(all.mixed_area, area);
  Points density;
  model.force_density(x, density);
  EXPECT_EQ(density, all.density);
  for (int i = 0; i < m.num_vertices(); ++i) EXPECT_EQ(density.row(i), f.row(i) / area[i]);
  EXPECT_EQ(model.elastic_energy(x), elastic.energy(x));
  EXPECT_FALSE(model.bending_energy(x).has_value());  // C is not energy-based
  EXPECT_FALSE(model.volume_energy(x).has_value());
  EXPECT_DOUBLE_EQ(model.reference_volume(), enclosed_volume(m.topology(), m.positions()));
}

TEST(MembraneModel, EnergyBasedBendingAndVolumeHook) {
  const TriMesh m = sphere_mesh(MeshFamily::MT1, 1);
  const Points x = deformed(m);
  MembraneParameters p;
  p.kS = 2;
  p.kB = 0.1;
  p.bending = make_bending_method("A");
  const MembraneModel plain(m, p);
  p.volume_force = std::make_shared<TestVolumePenalty>(3.0);
  const MembraneModel with_volume(m, p);
  ASSERT_TRUE(plain.bending_energy(x).has_value());
  EXPECT_EQ(*plain.bending_energy(x), *p.bending->energy(m.topology(), x, 0.1));
  Points f0, f1;
  plain.forces(x, f0);
  with_volume.forces(x, f1);
  Points extra = Points::Zero(m.num_vertices(), 3);
  p.volume_force->add_forces(m.topology(), x, plain.reference_volume(), extra);
  EXPECT_GT(extra.cwiseAbs().maxCoeff(), 0.0);
  EXPECT_EQ(f1, Points(f0 + extra));
  const double dv = enclosed_volume(m.topology(), x) - plain.reference_volume();
  EXPECT_DOUBLE_EQ(*with_volume.volume_energy(x), 1.5 * dv * dv);
}

TEST(MembraneModel, SpontaneousCurvatureAndAdeReachTheBendingMethod) {
  // docs/conventions.md §5: the model hands the method kB with c0 and ADE; A refuses them.
  const TriMesh m = sphere_mesh(MeshFamily::MT1, 1);
  const Points x = deformed(m);
  MembraneParameters p;
  p.kS = 2;
  p.kB = 0.1;
  p.bending = make_bending_method("J");
  const MembraneModel plain(m, p);
  p.bending_terms.c0 = 0.8;
  p.bending_terms.ade_alpha = 2;
  p.bending_terms.ade_d = 0.05;
  p.bending_terms.ade_area = 12;
  const MembraneModel with_terms(m, p);
  Points f0, f1, b0, b1;
  plain.forces(x, f0);
  with_terms.forces(x, f1);
  p.bending->forces(m.topology(), x, 0.1, b0);
  p.bending->forces(m.topology(), x, p.bending_parameters(), b1);
  EXPECT_GT((b1 - b0).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_LT((f1 - f0 - (b1 - b0)).cwiseAbs().maxCoeff(), 1e-12 * f1.cwiseAbs().maxCoeff());
  EXPECT_EQ(*with_terms.bending_energy(x), *p.bending->energy(m.topology(), x, p.bending_parameters()));
  p.bending = make_bending_method("A");
  EXPECT_THROW(MembraneModel(m, p), Error);
  p.bending = make_bending_method("C");
  p.kB = 0;
  EXPECT_THROW(MembraneModel(m, p), Error);  // c0 without bending
}

TEST(MembraneModel, ConcurrentCallsAgree) {
  // Const methods allocate their scratch per call: two threads on one model get the serial result.
  const TriMesh m = sphere_mesh(MeshFamily::MT1, 2);
  const Points x = deformed(m);
  MembraneParameters p;
  p.kS = 1;
  p.kB = 0.05;
  p.bending = make_bending_method("E");
  const auto model = std::make_shared<const MembraneModel>(m, p);
  Points serial;
  model->force_density(x, serial);
  Points a, b;
  std::thread ta([&] { for (int k = 0; k < 5; ++k) model->force_density(x, a); });
  std::thread tb([&] { for (int k = 0; k < 5; ++k) model->force_density(x, b); });
  ta.join();
  tb.join();
  EXPECT_EQ(a, serial);
  EXPECT_EQ(b, serial);
}

TEST(MembraneModel, RefusesBadParameters) {
  const TriMesh m = sphere_mesh(MeshFamily::MT1, 0);
  MembraneParameters p;
  p.kS = 0;
  EXPECT_THROW(MembraneModel(m, p), Error);
  p.kS = 1;
  p.kB = -1;
  EXPECT_THROW(MembraneModel(m, p), Error);
  p.kB = 1;  // no bending method
  EXPECT_THROW(MembraneModel(m, p), Error);
  p.kB = 0;
  p.elastic_law = "mooney-rivlin";  // unknown
  EXPECT_THROW(MembraneModel(m, p), Error);
  p.elastic_law = "skalak";
  p.skalak_c = -0.5;  // area modulus 0: not admissible
  EXPECT_THROW(MembraneModel(m, p), Error);
  p.skalak_c = 2;
  EXPECT_EQ(MembraneModel(m, p).elastic_law().name(), "Skalak");
  p.elastic_law = "neo-hookean";
  const MembraneModel ok(m, MembraneParameters{});
  Points f;
  EXPECT_THROW(ok.forces(Points::Zero(3, 3), f), Error);
}
