// A snapshot of several bodies is one mesh of all their triangles with a "body" field; one body is
// its membrane's mesh as before.
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

#include "bendlab/capsule/bodies_snapshot.hpp"
#include "bendlab/mesh/generators.hpp"
#include "bendlab/membrane/membrane_model.hpp"
#include "bendlab/mesh/mesh_io.hpp"
#include "file_test_support.hpp"

namespace fs = std::filesystem;
using bendlab::test_support::slurp;
using namespace bendlab;

TEST(BodiesSnapshot, SeveralBodiesAreOneMeshWithTheirIndex) {
  const TriMesh sphere = icosahedron();
  MembraneParameters p;
  const MembraneModel membrane(sphere, p);
  const Eigen::Index n = membrane.num_vertices();
  Points x(2 * n, 3);
  x.topRows(n) = sphere.positions();
  x.bottomRows(n) = sphere.positions();
  x.bottomRows(n).col(0).array() += 3;
  const fs::path one = fs::temp_directory_path() / ("bendlab_bodies_one_" + std::to_string(::getpid()) + ".vtp");
  const fs::path two = fs::temp_directory_path() / ("bendlab_bodies_two_" + std::to_string(::getpid()) + ".vtp");
  write_bodies_snapshot(one, {{&membrane, 0}}, x.topRows(n));
  const fs::path plain = fs::temp_directory_path() / ("bendlab_bodies_plain_" + std::to_string(::getpid()) + ".vtp");
  write_mesh(plain, membrane.topology(), x.topRows(n));
  EXPECT_EQ(slurp(one), slurp(plain));
  write_bodies_snapshot(two, {{&membrane, 0}, {&membrane, n}}, x);
  const std::string text = slurp(two);
  EXPECT_NE(text.find("NumberOfPoints=\"" + std::to_string(2 * n) + "\""), std::string::npos);
  EXPECT_NE(text.find("NumberOfPolys=\"" + std::to_string(2 * membrane.topology().num_faces()) + "\""),
            std::string::npos);
  EXPECT_NE(text.find("Name=\"body\""), std::string::npos);
  EXPECT_THROW(write_bodies_snapshot(two, {{&membrane, 0}, {&membrane, n + 1}}, x), Error);
  EXPECT_THROW(write_bodies_snapshot(two, {{&membrane, 0}}, x), Error);
  for (const fs::path& f : {one, two, plain}) fs::remove(f);
}
