// Cell kinds in physical units (flow/cell_kind.hpp): the red blood cell's size against the
// literature's (diameter 7.82 um, area about 135 um^2, volume about 94 um^3; CELLS_IN_CHANNELS.md
// section 2) and its membrane in lattice units against the unit conversions.
#include <gtest/gtest.h>

#include <fmt/format.h>

#include <cmath>

#include "bendlab/flow/cell_kind.hpp"
#include "bendlab/geometry/measures.hpp"

using namespace bendlab;

TEST(CellKind, RedBloodCellHasThePhysicalSize) {
  CellKindSpec spec;
  spec.mesh = "mt1:1280";
  const CellKind rbc = make_cell_kind(spec);
  const Points& x = rbc.reference_um.positions();
  const double diameter = x.col(0).maxCoeff() - x.col(0).minCoeff();
  EXPECT_NEAR(diameter, 7.82, 0.03);
  EXPECT_LT(x.col(2).maxCoeff() - x.col(2).minCoeff(), 3.0);  // biconcave disc about e_z, thinner than 3 um
  EXPECT_NEAR(rbc.area_um2, 135, 0.03 * 135);
  EXPECT_NEAR(rbc.volume_um3, 94, 0.03 * 94);
  EXPECT_LT(volume_centroid(rbc.reference_um.topology(), x).norm(), 1e-12);
  EXPECT_GT(rbc.mean_edge_um, 0.3);
  EXPECT_LT(rbc.mean_edge_um, 0.6);
}

TEST(CellKind, LatticeMembraneCarriesTheConvertedModuli) {
  CellKindSpec spec;
  spec.mesh = "mt1:320";
  const CellKind rbc = make_cell_kind(spec);
  lbm::FlowUnitsInput in;
  in.diameter_um = 10;
  in.length_um = 20;
  in.dx_um = 0.5;
  in.tau = 1.0;
  in.pseudo_shear_rate = 100;
  const lbm::FlowUnits u = lbm::flow_units(in);
  const auto m = lattice_membrane(rbc, u);
  EXPECT_DOUBLE_EQ(m->parameters().kS, u.to_lattice_modulus(3 * 5.3e-6));
  EXPECT_DOUBLE_EQ(m->parameters().kB, u.to_lattice_energy(2e-19));
  EXPECT_EQ(&m->topology(), &rbc.reference_um.topology());  // shared, not copied
  EXPECT_NEAR((m->reference_positions() * 0.5 - rbc.reference_um.positions()).cwiseAbs().maxCoeff(), 0.0, 1e-12);
  // At rest in its reference shape the membrane exerts no force (the volume force is zero there,
  // and Method C's bending force is what eq. (10) gives on the biconcave shape, not zero).
  Points F;
  m->forces(m->reference_positions(), F);
  Points Fb = F;
  CellKindSpec no_bending = spec;
  no_bending.bending_modulus = 0;
  lattice_membrane(make_cell_kind(no_bending), u)->forces(m->reference_positions(), Fb);
  EXPECT_LT(Fb.cwiseAbs().maxCoeff(), 1e-12 * F.cwiseAbs().maxCoeff() + 1e-300);
}

TEST(CellKind, RefusesBadParameters) {
  CellKindSpec s;
  s.shape = "platelet";
  EXPECT_THROW(make_cell_kind(s), Error);
  s = CellKindSpec{};
  s.shear_modulus = -1;
  EXPECT_THROW(check_cell_kind(s), Error);
  s = CellKindSpec{};
  s.bending_modulus = std::nan("");
  EXPECT_THROW(check_cell_kind(s), Error);
  s = CellKindSpec{};
  s.skalak_c = -0.5;
  EXPECT_THROW(check_cell_kind(s), Error);
  s = CellKindSpec{};
  s.radius_um = 0;
  EXPECT_THROW(check_cell_kind(s), Error);
}

TEST(CellKind, WarnsOfAMeshTooCoarseForTheLattice) {
  CellKindSpec spec;
  spec.mesh = "mt1:320";  // edges of about 0.9 um
  const CellKind coarse = make_cell_kind(spec);
  const auto w = mesh_leak_warning(coarse, 0.25);
  ASSERT_TRUE(w.has_value());
  EXPECT_NE(w->find(fmt::format("{:.2g} times", coarse.mean_edge_um / 0.25)), std::string::npos) << *w;
  EXPECT_FALSE(mesh_leak_warning(coarse, 1.0).has_value());
}
