// Contact forces between cells and with the wall (contact.hpp): the law's shape, forces as the
// exact negative gradient of the energy, Newton's third law, and the cell list against the plain
// all-pairs reference with nearest periodic images.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "bendlab/suspension/contact.hpp"

using namespace bendlab;

namespace {

// Random vertices of `cells` cells of `per_cell` vertices each, spread over the vessel's box,
// unwrapped by whole periods here and there.
Points random_cloud(const Vessel& v, int cells, int per_cell, std::vector<int>& cell_of, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-0.5, 0.5);
  std::uniform_int_distribution<int> shift(-1, 1);
  Points x(cells * per_cell, 3);
  cell_of.resize(x.rows());
  for (int c = 0; c < cells; ++c) {
    for (int k = 0; k < per_cell; ++k) {
      const int i = c * per_cell + k;
      cell_of[i] = c;
      Vec3 p(u(rng) * v.length(), u(rng) * v.width(), u(rng) * v.height());
      if (v.kind() == VesselKind::Tube) {
        const double r = 0.5 * v.diameter() * std::sqrt(0.5 + u(rng)), phi = 6.283185307179586 * u(rng);
        p.y() = r * std::cos(phi);
        p.z() = r * std::sin(phi);
      }
      p += Vec3(shift(rng) * v.length(), v.periodic(1) ? shift(rng) * v.width() : 0.0, 0.0);
      x.row(i) = p.transpose();
    }
  }
  return x;
}

double reference_energy(const Vessel& v, const ContactLaw& law, const Points& x, const std::vector<int>& cell_of, Points& F) {
  F.setZero(x.rows(), 3);
  double e = 0;
  for (Eigen::Index i = 0; i < x.rows(); ++i) {
    for (Eigen::Index j = i + 1; j < x.rows(); ++j) {
      if (cell_of[i] == cell_of[j]) continue;
      const Vec3 d = v.minimum_image(row(x, i) - row(x, j));
      const double r = d.norm();
      if (r >= law.cutoff) continue;
      e += law.energy(r);
      F.row(i) += (law.force(r) / r * d).transpose();
      F.row(j) -= (law.force(r) / r * d).transpose();
    }
  }
  return e;
}

}  // namespace

TEST(ContactLaw, SmoothCappedAndZeroBeyondTheCutoff) {
  const ContactLaw law{2.5, 0.8};
  EXPECT_DOUBLE_EQ(law.force(0.0), 2.5);
  EXPECT_DOUBLE_EQ(law.force(-0.3), 2.5);
  EXPECT_EQ(law.force(0.8), 0.0);
  EXPECT_EQ(law.force(3.0), 0.0);
  EXPECT_EQ(law.energy(0.8), 0.0);
  // Zero slope at the cutoff: F(rc - h) = O(h^2).
  EXPECT_LT(law.force(0.8 - 1e-4), 1e-7);
  // F = -dU/dr, also past the wall (r < 0) where the energy grows linearly.
  for (double r : {-0.2, 0.05, 0.3, 0.6, 0.79}) {
    const double h = 1e-6;
    EXPECT_NEAR(-(law.energy(r + h) - law.energy(r - h)) / (2 * h), law.force(r), 1e-8) << r;
  }
  EXPECT_THROW((ContactLaw{-1, 1}.validate()), Error);
  EXPECT_THROW((ContactLaw{1, 0}.validate()), Error);
  EXPECT_NO_THROW((ContactLaw{1, 1}.validate()));
}

TEST(ContactSearch, CellListEqualsAllPairsWithPeriodicImages) {
  for (const Vessel& v : {Vessel::channel(4.0, 3.0, 5.0), Vessel::tube(4.0, 2.5), Vessel::box(2.0, 1.5, 1.2)}) {
    std::vector<int> cell_of;
    const Points x = random_cloud(v, 5, 60, cell_of, 7);
    const ContactLaw law{1.3, 0.45};
    ContactSearch search;
    Points F = Points::Zero(x.rows(), 3), Fref;
    const double e = search.add_cell_contact(v, law, x, cell_of, F);
    const double eref = reference_energy(v, law, x, cell_of, Fref);
    ASSERT_GT(eref, 0) << v.describe();  // the cloud is dense enough to have contacts
    EXPECT_NEAR(e, eref, 1e-12 * eref) << v.describe();
    EXPECT_LT((F - Fref).cwiseAbs().maxCoeff(), 1e-12) << v.describe();
    // Newton's third law: the contact forces sum to zero.
    EXPECT_LT(F.colwise().sum().norm(), 1e-12) << v.describe();
    // A second call on the same workspace gives the same.
    Points F2 = Points::Zero(x.rows(), 3);
    EXPECT_EQ(search.add_cell_contact(v, law, x, cell_of, F2), e);
    EXPECT_EQ(F2, F);
  }
}

// The Verlet list against the search in every call, bit for bit, along a random walk of the
// vertices: steps below the skin (the list is kept), jumps beyond it and across the period (it is
// rebuilt), a changed cell and a changed cutoff (rebuilt). The energy is the same sum in another
// order.
TEST(ContactSearch, VerletListEqualsTheSearchInEveryCall) {
  for (const Vessel& v : {Vessel::channel(4.0, 3.0, 5.0), Vessel::tube(4.0, 2.5), Vessel::box(2.0, 1.5, 1.2)}) {
    std::vector<int> cell_of;
    Points x = random_cloud(v, 5, 60, cell_of, 21);
    ContactLaw law{1.3, 0.45};
    ContactSearch listed, searched;
    std::mt19937_64 rng(5);
    std::normal_distribution<double> step(0.0, 0.01);
    int calls = 0;
    for (int s = 0; s < 60; ++s) {
      if (s == 20) x.col(0).array() += v.length();  // every vertex by a whole period: same forces, new list
      if (s == 30) cell_of[7] = 4;                  // a vertex changes cell
      if (s == 40) law.cutoff = 0.4;
      for (Eigen::Index i = 0; i < x.rows(); ++i)
        for (int a = 0; a < 3; ++a) x(i, a) += step(rng);
      Points F = Points::Zero(x.rows(), 3), G = Points::Zero(x.rows(), 3);
      const double e = listed.add_cell_contact(v, law, x, cell_of, F);
      const double eref = searched.add_cell_contact_reference(v, law, x, cell_of, G);
      ++calls;
      ASSERT_EQ(F, G) << v.describe() << " call " << s;
      ASSERT_GT(eref, 0) << v.describe();
      EXPECT_NEAR(e, eref, 1e-13 * eref) << v.describe() << " call " << s;
    }
    EXPECT_EQ(searched.list_builds(), calls);
    EXPECT_GE(listed.list_builds(), 4) << v.describe();  // the first call, the period, the cell, the cutoff
    EXPECT_LT(listed.list_builds(), calls / 2) << v.describe();
  }
}

// A cell thrown far off along an axis without a period (a run blowing up) does not ask for bins
// by the million (fifty million here before, and an overflowing bin index where two axes spread):
// the search still finds every pair.
TEST(ContactSearch, FarFlungVertexNeedsNoBinsBeyondMemory) {
  const Vessel v = Vessel::channel(4.0, 3.0, 5.0);
  std::vector<int> cell_of;
  Points x = random_cloud(v, 5, 60, cell_of, 3);
  x(0, 2) = 1e15;
  const ContactLaw law{1.3, 0.45};
  ContactSearch search;
  Points F = Points::Zero(x.rows(), 3), Fref;
  const double e = search.add_cell_contact(v, law, x, cell_of, F);
  const double eref = reference_energy(v, law, x, cell_of, Fref);
  ASSERT_GT(eref, 0);
  EXPECT_NEAR(e, eref, 1e-12 * eref);
  EXPECT_LT((F - Fref).cwiseAbs().maxCoeff(), 1e-12);
}

// A vertex's contact force is summed over its partners in row order: a far cell appended to the
// rows (which moves the bins of the axes without a period) leaves every other force unchanged bit
// for bit, and so does leaving out a cell that touches no other (rows keep their order). This is
// what lets a rank of the MPI suspension compute its cells' forces from the nearby cells only.
TEST(ContactSearch, ForcesDoNotDependOnFarVertices) {
  for (const Vessel& v : {Vessel::channel(4.0, 3.0, 5.0), Vessel::tube(4.0, 2.5), Vessel::box(2.0, 1.5, 1.2)}) {
    std::vector<int> cell_of;
    const Points x = random_cloud(v, 5, 60, cell_of, 13);
    const ContactLaw law{1.3, 0.45};
    ContactSearch search;
    Points F = Points::Zero(x.rows(), 3);
    search.add_cell_contact(v, law, x, cell_of, F);
    ASSERT_GT(F.cwiseAbs().maxCoeff(), 0.0) << v.describe();
    // A sixth cell far beyond the walls, in the middle of the rows' order: cell 2's rows move.
    const Eigen::Index far_rows = 30, split = 2 * 60;
    Points y(x.rows() + far_rows, 3);
    std::vector<int> cell_of_y;
    for (Eigen::Index i = 0; i < split; ++i) y.row(i) = x.row(i), cell_of_y.push_back(cell_of[i]);
    for (Eigen::Index k = 0; k < far_rows; ++k) {
      y.row(split + k) << 0.01 * static_cast<double>(k), 0.02 * static_cast<double>(k), 3.0 * v.height() + 0.03 * static_cast<double>(k);
      cell_of_y.push_back(9);
    }
    for (Eigen::Index i = split; i < x.rows(); ++i) y.row(far_rows + i) = x.row(i), cell_of_y.push_back(cell_of[i]);
    Points G = Points::Zero(y.rows(), 3);
    search.add_cell_contact(v, law, y, cell_of_y, G);
    EXPECT_EQ(G.topRows(split), F.topRows(split)) << v.describe();
    EXPECT_EQ(G.middleRows(split, far_rows).cwiseAbs().maxCoeff(), 0.0) << v.describe();
    EXPECT_EQ(G.bottomRows(x.rows() - split), F.bottomRows(x.rows() - split)) << v.describe();
  }
}

TEST(ContactSearch, ForcesAreMinusTheEnergyGradient) {
  const Vessel v = Vessel::channel(3.0, 2.0, 2.0);
  std::vector<int> cell_of;
  Points x = random_cloud(v, 3, 40, cell_of, 11);
  const ContactLaw law{0.7, 0.5};
  ContactSearch search;
  Points F = Points::Zero(x.rows(), 3), scratch = Points::Zero(x.rows(), 3);
  search.add_cell_contact(v, law, x, cell_of, F);
  const double h = 1e-6;
  int checked = 0;
  for (Eigen::Index i = 0; i < x.rows(); i += 3) {
    for (int a = 0; a < 3; ++a) {
      Points xp = x, xm = x;
      xp(i, a) += h;
      xm(i, a) -= h;
      const double ep = search.add_cell_contact(v, law, xp, cell_of, scratch);
      const double em = search.add_cell_contact(v, law, xm, cell_of, scratch);
      EXPECT_NEAR(-(ep - em) / (2 * h), F(i, a), 1e-6) << i << " " << a;
      checked += F(i, a) != 0 ? 1 : 0;
    }
  }
  EXPECT_GT(checked, 10);
}

TEST(ContactSearch, OneCellFeelsNothingAndFarCellsFeelNothing) {
  const Vessel v = Vessel::channel(3.0, 2.0, 2.0);
  std::vector<int> cell_of;
  const Points x = random_cloud(v, 1, 80, cell_of, 5);
  ContactSearch search;
  Points F = Points::Zero(x.rows(), 3);
  EXPECT_EQ(search.add_cell_contact(v, ContactLaw{1, 0.5}, x, cell_of, F), 0.0);
  EXPECT_EQ(F.cwiseAbs().maxCoeff(), 0.0);
  // Two vertices of different cells 0.51 apart, cutoff 0.5: no force; 0.49: a force.
  Points two(2, 3);
  two << 0, 0, 0, 0.51, 0, 0;
  const std::vector<int> owners = {0, 1};
  Points F2 = Points::Zero(2, 3);
  search.add_cell_contact(v, ContactLaw{1, 0.5}, two, owners, F2);
  EXPECT_EQ(F2.cwiseAbs().maxCoeff(), 0.0);
  two(1, 0) = 0.49;
  search.add_cell_contact(v, ContactLaw{1, 0.5}, two, owners, F2);
  EXPECT_LT(F2(0, 0), 0.0);  // pushed apart
  EXPECT_GT(F2(1, 0), 0.0);
  // Through the periodic boundary: x = -0.9 and +0.9 in a period of 2 are 0.2 apart.
  two << -0.9, 0, 0, 0.9 + 2.0, 0, 0;  // the second one unwrapped by a period
  Points F3 = Points::Zero(2, 3);
  search.add_cell_contact(v, ContactLaw{1, 0.5}, two, owners, F3);
  EXPECT_GT(F3(0, 0), 0.0);  // pushed towards +x, away from its neighbour's image at -1.1
  EXPECT_NEAR(F3(0, 0), (ContactLaw{1, 0.5}.force(0.2)), 1e-12);
}

TEST(WallContact, PushesIntoTheFluidAndIsTheEnergyGradient) {
  for (const Vessel& v : {Vessel::tube(4.0, 2.0), Vessel::channel(4.0, 2.0, 2.0)}) {
    const ContactLaw law{2.0, 0.4};
    Points x(4, 3);
    x << 0.1, 1.8, 0.0,   // 0.2 from the tube's wall (and far from the channel's)
        0.0, 0.0, -1.75,  // 0.25 from the bottom wall
        0.3, 0.2, 0.1,    // far from both
        0.0, 0.0, 2.1;    // past the top wall
    Points F = Points::Zero(4, 3);
    const double e = add_wall_contact(v, law, x, F);
    EXPECT_GT(e, 0);
    for (Eigen::Index i = 0; i < x.rows(); ++i) {
      const Vec3 f = row(F, i), p = row(x, i);
      EXPECT_GE(f.dot(v.wall_normal(p)), 0.0);
      EXPECT_NEAR(f.norm(), law.force(v.wall_distance(p)), 1e-12);
      for (int a = 1; a < 3; ++a) {
        const double h = 1e-7;
        Points xp = x, xm = x, scratch = Points::Zero(4, 3);
        xp(i, a) += h;
        xm(i, a) -= h;
        const double d = -(add_wall_contact(v, law, xp, scratch) - add_wall_contact(v, law, xm, scratch)) / (2 * h);
        EXPECT_NEAR(d, F(i, a), 1e-6) << v.describe() << " " << i << " " << a;
      }
    }
    EXPECT_NEAR(F(3, 2), -2.0, 1e-12);  // capped, towards the fluid
  }
}
