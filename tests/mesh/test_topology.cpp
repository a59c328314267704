#include <gtest/gtest.h>

#include "bendlab/mesh/trimesh.hpp"

using namespace bendlab;

namespace {
// A tetrahedron with outward faces.
Points tetra_points() {
  Points p(4, 3);
  p << 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1;
  return p;
}
Faces tetra_faces() {
  Faces f(4, 3);
  f << 0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3;
  return f;
}
}  // namespace

TEST(Topology, TetrahedronCounts) {
  TriMesh m(tetra_points(), tetra_faces());
  EXPECT_EQ(m.topology().num_edges(), 6);
  EXPECT_EQ(m.topology().euler_characteristic(), 2);
  for (int i = 0; i < 4; ++i) EXPECT_EQ(m.topology().valence(i), 3);
}

TEST(Topology, RingsAreCounterClockwiseFans) {
  TriMesh m(tetra_points(), tetra_faces());
  const Topology& t = m.topology();
  for (int i = 0; i < t.num_vertices(); ++i) {
    const int b = t.ring_begin(i), d = t.valence(i);
    for (int k = 0; k < d; ++k) {
      const int f = t.ring_faces()[b + k], c = t.ring_corners()[b + k];
      ASSERT_EQ(t.faces()(f, c), i);
      EXPECT_EQ(t.faces()(f, (c + 1) % 3), t.ring_vertices()[b + k]);
      EXPECT_EQ(t.faces()(f, (c + 2) % 3), t.ring_vertices()[b + (k + 1) % d]);
      const int e = t.ring_edges()[b + k];
      const int a = t.edge_vertices()(e, 0), bb = t.edge_vertices()(e, 1);
      EXPECT_TRUE((a == i && bb == t.ring_vertices()[b + k]) || (bb == i && a == t.ring_vertices()[b + k]));
    }
  }
}

TEST(Topology, EdgeFacesAndOpposites) {
  TriMesh m(tetra_points(), tetra_faces());
  const Topology& t = m.topology();
  for (int e = 0; e < t.num_edges(); ++e) {
    const int a = t.edge_vertices()(e, 0), b = t.edge_vertices()(e, 1);
    EXPECT_LT(a, b);
    for (int s = 0; s < 2; ++s) {
      const int f = t.edge_faces()(e, s), o = t.edge_opposite()(e, s);
      int c = 0;
      while (t.faces()(f, c) != o) ++c;
      EXPECT_EQ(t.face_edges()(f, c), e);
      EXPECT_EQ(t.edge_opposite_corners()(e, s), c);
      // f0 traverses a -> b, f1 traverses b -> a.
      const int from = t.faces()(f, (c + 1) % 3), to = t.faces()(f, (c + 2) % 3);
      EXPECT_EQ(from, s == 0 ? a : b);
      EXPECT_EQ(to, s == 0 ? b : a);
    }
  }
}

TEST(MeshValidation, RefusesEachProblemByName) {
  auto expect_problem = [](MeshProblem want, auto&& make) {
    try {
      make();
      ADD_FAILURE() << "no error for " << to_string(want);
    } catch (const MeshError& e) {
      EXPECT_EQ(e.problem(), want) << e.what();
    }
  };
  expect_problem(MeshProblem::IndexOutOfRange, [] {
    Faces f = tetra_faces();
    f(2, 1) = 7;
    TriMesh(tetra_points(), f);
  });
  expect_problem(MeshProblem::RepeatedIndex, [] {
    Faces f = tetra_faces();
    f(1, 2) = f(1, 0);
    TriMesh(tetra_points(), f);
  });
  expect_problem(MeshProblem::BoundaryEdge, [] { TriMesh(tetra_points(), tetra_faces().topRows(3)); });
  expect_problem(MeshProblem::InconsistentOrientation, [] {
    Faces f = tetra_faces();
    std::swap(f(3, 1), f(3, 2));
    TriMesh(tetra_points(), f);
  });
  expect_problem(MeshProblem::InwardOrientation, [] {
    Faces f = tetra_faces();
    f.col(1).swap(f.col(2));
    TriMesh(tetra_points(), f);
  });
  expect_problem(MeshProblem::NonFinite, [] {
    Points p = tetra_points();
    p(3, 2) = std::numeric_limits<double>::quiet_NaN();
    TriMesh(p, tetra_faces());
  });
  // A scaled tetrahedron is a valid mesh at every scale where its areas and volume are
  // representable; beyond that it is refused as out of range, not as inward or zero-area.
  for (const double scale : {1e-50, 1e50}) EXPECT_NO_THROW(TriMesh(Points(scale * tetra_points()), tetra_faces()));
  expect_problem(MeshProblem::OutOfRange, [] { TriMesh(Points(1e80 * tetra_points()), tetra_faces()); });
  expect_problem(MeshProblem::OutOfRange, [] { TriMesh(Points(1e-80 * tetra_points()), tetra_faces()); });
  expect_problem(MeshProblem::ZeroArea, [] {
    Points p = tetra_points();
    p.row(3) = p.row(1);  // faces touching vertices 1 and 3 collapse to a segment
    p(3, 0) = 0.5;
    p.row(3) << 0.5, 0.5, 0;  // on the hypotenuse of the base: face (1,2,3) has zero area
    TriMesh(p, tetra_faces());
  });
  expect_problem(MeshProblem::UnreferencedVertex, [] {
    Points p(5, 3);
    p.topRows(4) = tetra_points();
    p.row(4) << 5, 5, 5;
    TriMesh(p, tetra_faces());
  });
  expect_problem(MeshProblem::NonManifoldEdge, [] {
    // Three tetrahedra glued on edge (0,1): the edge has six faces.
    Points p(6, 3);
    p << 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0, -1, 0, 0, 0, -1;
    Faces f(8, 3);
    f << 0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3,  //
        0, 1, 4, 0, 4, 5, 0, 5, 1, 1, 5, 4;
    TriMesh(p, f);
  });
  expect_problem(MeshProblem::NonManifoldVertex, [] {
    // Two tetrahedra sharing only vertex 0.
    Points p(7, 3);
    p << 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, -1, 0, 0, 0, -1, 0, 0, 0, -1;
    Faces f(8, 3);
    f << 0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3,  //
        0, 5, 4, 0, 4, 6, 0, 6, 5, 4, 5, 6;
    TriMesh(p, f, MeshOptions{true});
  });
}

TEST(MeshValidation, FlipOptionReversesInwardFaces) {
  Faces f = tetra_faces();
  f.col(1).swap(f.col(2));
  TriMesh m(tetra_points(), f, MeshOptions{true});
  EXPECT_EQ(m.faces().row(0), tetra_faces().row(0));
}

TEST(MeshValidation, RefusesMoreThanOneComponent) {
  // Two disjoint tetrahedra: each closed and outward, together not one surface (a capsule's
  // shape measures of them would describe no body).
  Points p(8, 3);
  p.topRows(4) = tetra_points();
  p.bottomRows(4) = tetra_points().array() + 5.0;
  Faces f(8, 3);
  f.topRows(4) = tetra_faces();
  f.bottomRows(4) = tetra_faces().array() + 4;
  try {
    TriMesh m(p, f);
    FAIL() << "two components were accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("several components: the mesh has 2 connected components"),
              std::string::npos)
        << e.what();
  }
}
