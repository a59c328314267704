#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "bendlab/mesh/mesh_io.hpp"

using namespace bendlab;
namespace fs = std::filesystem;

namespace {

// A regular octahedron with outward faces, scaled and nudged so that the coordinates need all
// 17 significant digits (a writer with fewer digits would not round-trip).
Points octahedron_points() {
  const double a = 1.0 / 3.0, b = std::sqrt(2.0), c = std::nextafter(M_PI / 7.0, 1.0);
  Points p(6, 3);
  p << a, 0, 0,  //
      -b, 0, 0,  //
      0, c, 0,   //
      0, -a, 0,  //
      0, 0, b,   //
      0, 0, -c;
  return p;
}
Faces octahedron_faces() {
  Faces f(8, 3);
  f << 0, 2, 4, 2, 1, 4, 1, 3, 4, 3, 0, 4, 2, 0, 5, 1, 2, 5, 3, 1, 5, 0, 3, 5;
  return f;
}

// A fresh folder per test, removed afterwards.
class MeshIo : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* t = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() / (std::string("bendlab_mesh_io_") + t->name() + "_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    topology_ = Topology::build(6, octahedron_faces());
  }
  void TearDown() override { fs::remove_all(dir_); }

  fs::path file(const std::string& name) const { return dir_ / name; }
  fs::path write_bytes(const std::string& name, const std::string& bytes) const {
    std::ofstream(file(name), std::ios::binary) << bytes;
    return file(name);
  }
  static std::string read_text(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
  }
  std::vector<std::string> files_in_dir() const {
    std::vector<std::string> names;
    for (const auto& e : fs::directory_iterator(dir_)) names.push_back(e.path().filename().string());
    return names;
  }

  fs::path dir_;
  TopologyPtr topology_;
};

// The message of the bendlab::Error (and not of any other exception) thrown by f.
template <typename F>
std::string error_of(F&& f) {
  try {
    f();
  } catch (const MeshError& e) {
    return std::string("unexpected MeshError: ") + e.what();
  } catch (const Error& e) {
    return e.what();
  }
  return "no error";
}

// Raw bytes of a binary PLY body, in either byte order.
class Bytes {
 public:
  explicit Bytes(bool big_endian) : big_(big_endian) {}
  template <typename T>
  Bytes& put(T v) {
    char b[sizeof(T)];
    std::memcpy(b, &v, sizeof(T));
    if (big_ != (std::endian::native == std::endian::big)) std::reverse(b, b + sizeof(T));
    s_.append(b, sizeof(T));
    return *this;
  }
  const std::string& str() const { return s_; }

 private:
  bool big_;
  std::string s_;
};

// The text of the DataArray with the given Name in a .vtp file ("" if absent).
std::string data_array(const std::string& vtp, const std::string& name) {
  const std::size_t a = vtp.find("Name=\"" + name + "\"");
  if (a == std::string::npos) return "";
  const std::size_t b = vtp.find('>', a) + 1, e = vtp.find("</DataArray>", b);
  return vtp.substr(b, e - b);
}
std::vector<double> numbers(const std::string& text) {
  std::istringstream in(text);
  std::vector<double> v;
  std::string t;
  while (in >> t) v.push_back(std::strtod(t.c_str(), nullptr));
  return v;
}
std::string attribute(const std::string& text, const std::string& name) {
  const std::size_t a = text.find(name + "=\"");
  if (a == std::string::npos) return "";
  const std::size_t b = a + name.size() + 2;
  return text.substr(b, text.find('"', b) - b);
}

}  // namespace

// --- round trips -------------------------------------------------------------------------------

TEST_F(MeshIo, RoundTripIsExactForEveryReadableFormat) {
  const Points x = octahedron_points();
  for (const char* name : {"m.off", "m.obj", "m.ply", "M.OFF", "m.Ply"}) {
    SCOPED_TRACE(name);
    write_mesh(file(name), *topology_, x);
    const RawMesh raw = read_raw_mesh(file(name));
    EXPECT_EQ(raw.positions, x);  // bit-for-bit
    EXPECT_EQ(raw.faces, octahedron_faces());
    const TriMesh m = read_mesh(file(name));
    EXPECT_EQ(m.positions(), x);
    EXPECT_EQ(m.faces(), octahedron_faces());
  }
  EXPECT_EQ(files_in_dir().size(), 5u);  // no temporary files left behind
}

TEST_F(MeshIo, PlyWithFieldsReadsBackAndNamesTheProperties) {
  const Points x = octahedron_points();
  VertexFields fields;
  fields.scalars.push_back({"H", Scalars::LinSpaced(6, -1.0 / 3, 7.0 / 3)});
  fields.vectors.push_back({"force", x * 3.0});
  write_mesh(file("f.ply"), *topology_, x, fields);
  const RawMesh raw = read_raw_mesh(file("f.ply"));  // the extra properties are skipped
  EXPECT_EQ(raw.positions, x);
  EXPECT_EQ(raw.faces, octahedron_faces());
  const std::string text = read_text(file("f.ply"));
  const std::string header = text.substr(0, text.find("end_header"));
  for (const char* p : {"property double x\n", "property double H\n", "property double force_x\n",
                        "property double force_y\n", "property double force_z\n", "element vertex 6\n",
                        "element face 8\n", "format binary_little_endian 1.0\n"})
    EXPECT_NE(header.find(p), std::string::npos) << p;
  // Header, 6 vertices of 7 doubles, 8 faces of one uchar and three int32.
  EXPECT_EQ(text.size(), text.find("end_header\n") + 11 + 6 * 7 * 8 + 8 * (1 + 3 * 4));
}

TEST_F(MeshIo, VtpHoldsPointsPolysAndNamedFields) {
  const Points x = octahedron_points();
  VertexFields fields;
  Scalars h(6);
  h << 1.0 / 7, 2, 3, 4, 5, -6;
  fields.scalars.push_back({"mean_curvature", h});
  fields.scalars.push_back({"area", Scalars::Constant(6, 0.5)});
  fields.vectors.push_back({"normal", x});
  write_mesh(file("s.vtp"), *topology_, x, fields);
  const std::string vtp = read_text(file("s.vtp"));
  EXPECT_EQ(attribute(vtp, "NumberOfPoints"), "6");
  EXPECT_EQ(attribute(vtp, "NumberOfPolys"), "8");

  const std::vector<double> p = numbers(data_array(vtp, "Points"));
  ASSERT_EQ(p.size(), 18u);
  for (int i = 0; i < 6; ++i)
    for (int k = 0; k < 3; ++k) EXPECT_EQ(p[3 * i + k], x(i, k));
  const std::vector<double> conn = numbers(data_array(vtp, "connectivity"));
  ASSERT_EQ(conn.size(), 24u);
  for (int f = 0; f < 8; ++f)
    for (int k = 0; k < 3; ++k) EXPECT_EQ(conn[3 * f + k], octahedron_faces()(f, k));
  const std::vector<double> offsets = numbers(data_array(vtp, "offsets"));
  ASSERT_EQ(offsets.size(), 8u);
  for (int f = 0; f < 8; ++f) EXPECT_EQ(offsets[f], 3 * (f + 1));

  const std::vector<double> hv = numbers(data_array(vtp, "mean_curvature"));
  ASSERT_EQ(hv.size(), 6u);
  for (int i = 0; i < 6; ++i) EXPECT_EQ(hv[i], h(i));
  EXPECT_EQ(numbers(data_array(vtp, "area")).size(), 6u);
  EXPECT_EQ(numbers(data_array(vtp, "normal")).size(), 18u);
  const std::size_t normal = vtp.find("Name=\"normal\"");
  EXPECT_EQ(attribute(vtp.substr(normal), "NumberOfComponents"), "3");
  EXPECT_EQ(attribute(vtp.substr(vtp.find("Name=\"area\"")), "NumberOfComponents"), "1");
  // Every DataArray is closed, and the document is closed.
  std::size_t opened = 0, closed = 0;
  for (std::size_t i = vtp.find("<DataArray"); i != std::string::npos; i = vtp.find("<DataArray", i + 1)) ++opened;
  for (std::size_t i = vtp.find("</DataArray>"); i != std::string::npos; i = vtp.find("</DataArray>", i + 1)) ++closed;
  EXPECT_EQ(opened, 6u);
  EXPECT_EQ(closed, 6u);
  EXPECT_NE(vtp.find("</VTKFile>"), std::string::npos);
}

TEST_F(MeshIo, FieldsAreIgnoredForOffAndObj) {
  VertexFields fields;
  fields.scalars.push_back({"H", Scalars::Zero(3)});  // wrong size, but not used
  write_mesh(file("a.off"), *topology_, octahedron_points(), fields);
  EXPECT_EQ(read_raw_mesh(file("a.off")).faces, octahedron_faces());
}

TEST_F(MeshIo, PvdListsTheFilesInOrder) {
  write_pvd(file("run.pvd"), {{0.0, "shape_0.vtp"}, {0.1, "shape_1.vtp"}, {0.25, "a&b.vtp"}});
  const std::string pvd = read_text(file("run.pvd"));
  EXPECT_NE(pvd.find("type=\"Collection\""), std::string::npos);
  const std::size_t a = pvd.find("file=\"shape_0.vtp\""), b = pvd.find("file=\"shape_1.vtp\""),
                    c = pvd.find("file=\"a&amp;b.vtp\"");
  ASSERT_NE(a, std::string::npos);
  ASSERT_NE(b, std::string::npos);
  ASSERT_NE(c, std::string::npos);
  EXPECT_LT(a, b);
  EXPECT_LT(b, c);
  EXPECT_EQ(std::stod(attribute(pvd.substr(pvd.rfind("<DataSet", b)), "timestep")), 0.1);
  EXPECT_THROW(write_pvd(file("bad.pvd"), {{NAN, "x.vtp"}}), Error);
  EXPECT_FALSE(fs::exists(file("bad.pvd")));
}

// --- hand-written files --------------------------------------------------------------------------

TEST_F(MeshIo, OffWithCommentsQuadsAndExtraValues) {
  const auto p = write_bytes("cube.off",
                             "# a unit cube\n"
                             "OFF\n"
                             "\n"
                             "8 6 12   # counts\n"
                             "0 0 0\n1 0 0\n1 1 0\n0 1 0\n"
                             "0 0 1\r\n1 0 1\n1 1 1\n"
                             "# a comment between vertices\n"
                             "0 1 1 0.5 0.5 0.5\n"  // trailing colour values are ignored
                             "4 0 3 2 1\n4 4 5 6 7\n4 0 1 5 4\n4 1 2 6 5\n4 2 3 7 6\n"
                             "4 3 0 4 7 255 0 0\n");
  const RawMesh raw = read_raw_mesh(p);
  ASSERT_EQ(raw.positions.rows(), 8);
  EXPECT_EQ(raw.positions.row(7), Eigen::RowVector3d(0, 1, 1));
  ASSERT_EQ(raw.faces.rows(), 12);
  // Fan of (0 3 2 1): (0 3 2), (0 2 1); the last quad (3 0 4 7): (3 0 4), (3 4 7).
  EXPECT_EQ(raw.faces.row(0), Eigen::RowVector3i(0, 3, 2));
  EXPECT_EQ(raw.faces.row(1), Eigen::RowVector3i(0, 2, 1));
  EXPECT_EQ(raw.faces.row(10), Eigen::RowVector3i(3, 0, 4));
  EXPECT_EQ(raw.faces.row(11), Eigen::RowVector3i(3, 4, 7));
  const TriMesh m = read_mesh(p);  // a valid closed outward cube
  EXPECT_EQ(m.topology().euler_characteristic(), 2);
}

TEST_F(MeshIo, OffCountsOnTheHeaderLine) {
  const auto p = write_bytes("t.off", "OFF 4 4 6\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n");
  const TriMesh m = read_mesh(p);
  EXPECT_EQ(m.num_faces(), 4);
  EXPECT_EQ(m.faces().row(3), Eigen::RowVector3i(1, 2, 3));
}

TEST_F(MeshIo, ObjWithSlashFormsNegativeIndicesAndIgnoredLines) {
  const auto p = write_bytes("t.obj",
                             "# tetrahedron\nmtllib t.mtl\no tet\n"
                             "v 0 0 0\nv 1 0 0\nv 0 1 0\n"
                             "vn 0 0 1\nvt 0.5 0.5\ng side\ns off\nusemtl red\n"
                             "f 1/1/1 3/1/1 2/1/1\n"
                             "v 0 0 1 1.0\n"  // w is ignored
                             "f -4//1 -3//1 -1//1\n"
                             "f 1/1 4/1 3/1\n"
                             "f -3 -2 -1\n");
  const RawMesh raw = read_raw_mesh(p);
  ASSERT_EQ(raw.positions.rows(), 4);
  EXPECT_EQ(raw.positions.row(3), Eigen::RowVector3d(0, 0, 1));
  Faces expected(4, 3);
  expected << 0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3;
  EXPECT_EQ(raw.faces, expected);
  EXPECT_NO_THROW(read_mesh(p));
}

TEST_F(MeshIo, ObjQuadIsFanTriangulated) {
  const auto p = write_bytes("q.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 2 2 2\nf 1 2 3 4 5\n");
  const RawMesh raw = read_raw_mesh(p);
  Faces expected(3, 3);
  expected << 0, 1, 2, 0, 2, 3, 0, 3, 4;
  EXPECT_EQ(raw.faces, expected);
}

TEST_F(MeshIo, AsciiPlyWithExtraPropertiesAndElements) {
  const auto p = write_bytes("t.ply",
                             "ply\r\n"
                             "format ascii 1.0\n"
                             "comment made by hand\n"
                             "obj_info nothing\n"
                             "element vertex 4\n"
                             "property float32 nx\n"
                             "property double z\n"
                             "property uchar red\n"
                             "property float y\n"
                             "property float x\n"
                             "element face 3\n"
                             "property uchar flags\n"
                             "property list uint8 int32 vertex_index\n"
                             "property list uchar float texcoord\n"
                             "element edge 2\n"
                             "property int vertex1\n"
                             "property int vertex2\n"
                             "end_header\n"
                             "0.5 0 255 0 0\n"
                             "0.5 0 1 0 1\n"
                             "0.5 0 2 1 0\n"
                             "0.5 1 3 0 0\n"
                             "7 3 0 2 1 0\n"
                             "7 4 0 1 2 3 2 0.5 0.5\n"  // a quad with texture coordinates
                             "\n"
                             "7 3 0 3 2 0\n"
                             "0 1\n"
                             "1 2\n");
  const RawMesh raw = read_raw_mesh(p);
  ASSERT_EQ(raw.positions.rows(), 4);
  EXPECT_EQ(raw.positions.row(1), Eigen::RowVector3d(1, 0, 0));
  EXPECT_EQ(raw.positions.row(2), Eigen::RowVector3d(0, 1, 0));
  EXPECT_EQ(raw.positions.row(3), Eigen::RowVector3d(0, 0, 1));
  Faces expected(4, 3);
  expected << 0, 2, 1, 0, 1, 2, 0, 2, 3, 0, 3, 2;
  EXPECT_EQ(raw.faces, expected);
}

TEST_F(MeshIo, BinaryBigEndianPlyWithMixedTypes) {
  // Tetrahedron: x, y, z as float, int16 and double; faces as uint16 counts and uint32 indices;
  // an extra element with a list between vertices and faces.
  const std::string header =
      "ply\nformat binary_big_endian 1.0\n"
      "element vertex 4\nproperty float x\nproperty uchar u\nproperty int16 y\nproperty double z\n"
      "element material 2\nproperty list uchar double values\nproperty char id\n"
      "element face 4\nproperty list ushort uint vertex_indices\nproperty float weight\n"
      "end_header\n";
  Bytes b(true);
  const float xs[4] = {0, 1.5f, 0, 0};
  const std::int16_t ys[4] = {0, 0, -2, 0};
  const double zs[4] = {0, 0, 0, 1.0 / 3.0};
  for (int i = 0; i < 4; ++i) b.put(xs[i]).put(std::uint8_t(9)).put(ys[i]).put(zs[i]);
  b.put(std::uint8_t(2)).put(1.0).put(2.0).put(std::int8_t(-1));
  b.put(std::uint8_t(0)).put(std::int8_t(5));
  const std::uint32_t faces[4][3] = {{0, 1, 2}, {0, 3, 1}, {0, 2, 3}, {1, 3, 2}};
  for (const auto& f : faces) b.put(std::uint16_t(3)).put(f[0]).put(f[1]).put(f[2]).put(0.25f);
  const auto p = write_bytes("be.ply", header + b.str());
  const RawMesh raw = read_raw_mesh(p);
  Points ex(4, 3);
  ex << 0, 0, 0, 1.5, 0, 0, 0, -2, 0, 0, 0, 1.0 / 3.0;
  EXPECT_EQ(raw.positions, ex);
  ASSERT_EQ(raw.faces.rows(), 4);
  for (int f = 0; f < 4; ++f)
    for (int k = 0; k < 3; ++k) EXPECT_EQ(raw.faces(f, k), static_cast<int>(faces[f][k]));
  EXPECT_NO_THROW(read_mesh(p));
}

TEST_F(MeshIo, BinaryLittleEndianPlyWithPentagon) {
  const std::string header =
      "ply\nformat binary_little_endian 1.0\nelement vertex 5\nproperty double x\nproperty double y\n"
      "property double z\nelement face 1\nproperty list int char vertex_indices\nend_header\n";
  Bytes b(false);
  for (int i = 0; i < 5; ++i) b.put(std::cos(0.4 * M_PI * i)).put(std::sin(0.4 * M_PI * i)).put(0.0);
  b.put(std::int32_t(5));
  for (int i = 0; i < 5; ++i) b.put(std::int8_t(i));
  const RawMesh raw = read_raw_mesh(write_bytes("le.ply", header + b.str()));
  ASSERT_EQ(raw.faces.rows(), 3);
  EXPECT_EQ(raw.faces.row(2), Eigen::RowVector3i(0, 3, 4));
  EXPECT_EQ(raw.positions(2, 0), std::cos(0.8 * M_PI));
}

// --- malformed input -------------------------------------------------------------------------------

struct BadFile {
  const char* name;
  std::string content;
  const char* position;  // the position the message must name
  const char* problem;   // a word of the problem the message must name
};

TEST_F(MeshIo, MalformedFilesGiveOneLineErrorsWithFileAndPosition) {
  const std::string ply_head = "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\n"
                               "property float y\nproperty float z\nelement face 1\n"
                               "property list uchar int vertex_indices\nend_header\n";
  Bytes tri(false);
  for (int i = 0; i < 9; ++i) tri.put(float(i == 0 || i == 4 || i == 8));
  const std::string verts = tri.str();
  const std::string good_face = Bytes(false).put(std::uint8_t(3)).put(0).put(1).put(2).str();
  const std::string neg_face = Bytes(false).put(std::uint8_t(3)).put(0).put(-1).put(2).str();

  const std::vector<BadFile> cases = {
      // bad headers
      {"h1.off", "", "line 0", "empty"},
      {"h2.off", "# only\nOOF\n1 0 0\n", "line 2", "header"},
      {"h3.off", "OFF BINARY\n", "line 1", "binary"},
      {"h4.off", "OFF\n3 one 0\n", "line 2", "counts"},
      {"h5.ply", "PLY\nformat ascii 1.0\nend_header\n", "line 1", "header"},
      {"h6.ply", "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n", "line 4", "end_header"},
      {"h7.ply", "ply\nformat text 1.0\nend_header\n", "line 2", "format"},
      {"h8.ply", "ply\nformat ascii 1.0\nelement vertex 1\nproperty real x\nend_header\n", "line 4", "type"},
      {"h9.ply", "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nend_header\n", "line 3",
       "'z'"},
      {"h10.ply", "ply\nformat ascii 1.0\nelement vertex 0\nproperty float x\nproperty float y\nproperty float z\n"
                  "end_header\n", "line 7", "face"},
      {"h11.ply", "ply\nformat ascii 1.0\nproperty float x\nend_header\n", "line 3", "property"},
      {"h12.ply", "ply\nelement vertex 0\nend_header\n", "line 3", "format"},
      // truncated data
      {"t1.off", "OFF\n3 1 0\n0.000 0.000 0.000\n1.000 0.000 0.000\n", "line 4", "truncated"},
      {"t2.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n", "line 5", "truncated"},
      {"t3.off", "OFF\n3 1 0\n0 0 0\n1 0\n0 1 0\n3 0 1 2\n", "line 4", "vertex 1"},
      {"t4.ply", ply_head + verts.substr(0, 30), "byte", "truncated"},
      {"t5.ply", ply_head + verts + good_face.substr(0, 9), "face 0 of 1", "truncated"},
      {"t6.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
                 "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1\n3 0 1 2\n",
       "line 12", "missing"},
      {"t7.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
                 "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1\n",
       "line 13", "3 items"},
      // non-numeric tokens
      {"n1.off", "OFF\n3 1 0\n0 0 0\n1 abc 0\n0 1 0\n3 0 1 2\n", "line 4", "'abc'"},
      {"n2.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1e\nf 1 2 3\n", "line 4", "'1e'"},
      {"n3.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
                 "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 nan0\n3 0 1 2\n",
       "line 12", "'nan0'"},
      {"n4.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
                 "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2.5\n",
       "line 13", "'2.5'"},
      // wrong counts
      {"c1.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n3 0 2 1\n", "line 7", "counts"},
      {"c2.off", "OFF\n2000000000 2000000000 0\n0 0 0\n", "line 2", "counts"},
      {"c3.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n4 0 1 2\n", "line 6", "4 corners"},
      {"c4.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n2 0 1\n", "line 6", "at least 3"},
      {"c5.ply", ply_head + verts + good_face + "x", "byte", "left over"},
      {"c6.ply", "ply\nformat binary_little_endian 1.0\nelement vertex 100000000\nproperty double x\nproperty double y\n"
                 "property double z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n" + verts,
       "line 3", "counts"},
      {"c7.ply", "ply\nformat ascii 1.0\nelement vertex 4000000000\nproperty float x\nproperty float y\n"
                 "property float z\nelement face 0\nproperty list uchar int vertex_indices\nend_header\n",
       "line 3", "too many"},
      {"c8.ply", ply_head + verts + Bytes(false).put(std::uint8_t(200)).put(0).str(), "face 0 of 1", "200 items"},
      {"c9.obj", "v 0 0 0\nv 1 0 0\nf 1 2\n", "line 3", "at least 3"},
      // negative or unparsable indices
      {"i1.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 -1 2\n", "line 6", "negative"},
      {"i2.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 x 2\n", "line 6", "'x'"},
      {"i3.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 -4\n", "line 4", "-4"},
      {"i4.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 0\n", "line 4", "index 0"},
      {"i5.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 /3\n", "line 4", "'/3'"},
      {"i6.ply", ply_head + verts + neg_face, "face 0 of 1", "-1"},
      {"i7.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 99999999999\n", "line 6", "too large"},
  };
  for (const BadFile& c : cases) {
    SCOPED_TRACE(c.name);
    const fs::path p = write_bytes(c.name, c.content);
    const std::string msg = error_of([&] { read_raw_mesh(p); });
    EXPECT_NE(msg.find(p.string()), std::string::npos) << msg;
    EXPECT_NE(msg.find(c.position), std::string::npos) << msg;
    EXPECT_NE(msg.find(c.problem), std::string::npos) << msg;
    EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
    // read_mesh reports the same read error, not a MeshError.
    EXPECT_EQ(error_of([&] { read_mesh(p); }), msg);
  }
}

TEST_F(MeshIo, MissingFileAndUnknownExtension) {
  const std::string missing = error_of([&] { read_raw_mesh(file("nothing.off")); });
  EXPECT_NE(missing.find("nothing.off"), std::string::npos) << missing;
  EXPECT_NE(missing.find("No such file or directory"), std::string::npos) << missing;
  const auto stl = write_bytes("m.stl", "solid\n");
  const std::string ext = error_of([&] { read_raw_mesh(stl); });
  EXPECT_NE(ext.find("m.stl"), std::string::npos) << ext;
  EXPECT_NE(ext.find("'.stl'"), std::string::npos) << ext;
  const std::string none = error_of([&] { read_raw_mesh(file("noext")); });
  EXPECT_NE(none.find("extension none"), std::string::npos) << none;
  fs::create_directories(file("dir.off"));
  EXPECT_NE(error_of([&] { read_raw_mesh(file("dir.off")); }).find("a folder"), std::string::npos);
}

TEST_F(MeshIo, SpecialFilesAreRefusedAtOnce) {
  // Opening a FIFO for reading would wait for a writer forever; it is refused before opening.
  const fs::path fifo = file("pipe.off");
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  const std::string e = error_of([&] { read_raw_mesh(fifo); });
  EXPECT_NE(e.find("pipe.off"), std::string::npos) << e;
  EXPECT_NE(e.find("FIFO"), std::string::npos) << e;
  const std::string dev = error_of([&] { read_raw_mesh("/dev/null.off"); });
  EXPECT_NE(dev.find("No such file"), std::string::npos) << dev;
}

TEST_F(MeshIo, ParseFromMemoryEqualsReadingTheFile) {
  const std::string off = "OFF\n4 4 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n";
  const RawMesh a = read_raw_mesh(write_bytes("t.off", off));
  const RawMesh b = parse_raw_mesh(off, "off", "memory.off");
  EXPECT_EQ(a.positions, b.positions);
  EXPECT_EQ(a.faces, b.faces);
  EXPECT_THROW(parse_raw_mesh(off, "stl", "memory.stl"), Error);
}

TEST_F(MeshIo, IndexPastTheLastVertexIsLeftToValidation) {
  const auto p = write_bytes("oor.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n");
  const RawMesh raw = read_raw_mesh(p);
  EXPECT_EQ(raw.faces.row(0), Eigen::RowVector3i(0, 1, 3));
  try {
    read_mesh(p);
    ADD_FAILURE() << "no MeshError";
  } catch (const MeshError& e) {
    EXPECT_EQ(e.problem(), MeshProblem::IndexOutOfRange);
    EXPECT_NE(std::string(e.what()).find(p.string()), std::string::npos) << e.what();
    EXPECT_EQ(std::string(e.what()).rfind(to_string(MeshProblem::IndexOutOfRange), 0), 0u) << e.what();
  }
}

TEST_F(MeshIo, ReadMeshCanFlipAnInwardMesh) {
  Faces inward = octahedron_faces();
  inward.col(1).swap(inward.col(2));
  std::string off = "OFF\n6 8 0\n";
  const Points x = octahedron_points();
  for (int i = 0; i < 6; ++i) off += std::to_string(x(i, 0)) + " " + std::to_string(x(i, 1)) + " " + std::to_string(x(i, 2)) + "\n";
  for (int f = 0; f < 8; ++f)
    off += "3 " + std::to_string(inward(f, 0)) + " " + std::to_string(inward(f, 1)) + " " + std::to_string(inward(f, 2)) + "\n";
  const auto p = write_bytes("in.off", off);
  EXPECT_THROW(read_mesh(p), MeshError);
  EXPECT_EQ(read_mesh(p, MeshOptions{true}).faces(), octahedron_faces());
}

// --- failed writes leave nothing -----------------------------------------------------------------

TEST_F(MeshIo, FailedWritesLeaveNoFile) {
  const Points x = octahedron_points();
  VertexFields short_field;
  short_field.scalars.push_back({"H", Scalars::Zero(5)});
  VertexFields bad_name;
  bad_name.scalars.push_back({"mean curvature", Scalars::Zero(6)});
  VertexFields clash;
  clash.vectors.push_back({"f", x});
  clash.scalars.push_back({"f_y", Scalars::Zero(6)});
  VertexFields reserved;
  reserved.scalars.push_back({"x", Scalars::Zero(6)});

  EXPECT_THROW(write_mesh(file("m.stl"), *topology_, x), Error);
  EXPECT_THROW(write_mesh(file("m.off"), *topology_, x.topRows(5)), Error);
  EXPECT_THROW(write_mesh(file("m.ply"), *topology_, x, short_field), Error);
  EXPECT_THROW(write_mesh(file("m.vtp"), *topology_, x, short_field), Error);
  EXPECT_THROW(write_mesh(file("m.vtp"), *topology_, x, bad_name), Error);
  EXPECT_THROW(write_mesh(file("m.ply"), *topology_, x, clash), Error);
  EXPECT_THROW(write_mesh(file("m.ply"), *topology_, x, reserved), Error);
  EXPECT_TRUE(files_in_dir().empty());
}

TEST_F(MeshIo, UnwritablePathThrowsAndLeavesNothing) {
  const Points x = octahedron_points();
  for (const char* name : {"m.off", "m.obj", "m.ply", "m.vtp"}) {
    SCOPED_TRACE(name);
    // A folder that does not exist.
    const fs::path p = file("missing_dir") / name;
    const std::string msg = error_of([&] { write_mesh(p, *topology_, x); });
    EXPECT_NE(msg.find(p.string()), std::string::npos) << msg;
    // A target that is a folder: the temporary file is written, the rename fails, and the
    // temporary file is removed again.
    const fs::path d = file(std::string("dir_") + name);
    fs::create_directories(d);
    EXPECT_NE(error_of([&] { write_mesh(d, *topology_, x); }), "no error");
    EXPECT_TRUE(fs::is_directory(d));
  }
  EXPECT_THROW(write_pvd(file("missing_dir") / "a.pvd", {{0.0, "a.vtp"}}), Error);
  std::vector<std::string> left = files_in_dir();
  std::sort(left.begin(), left.end());
  EXPECT_EQ(left, (std::vector<std::string>{"dir_m.obj", "dir_m.off", "dir_m.ply", "dir_m.vtp"}));
}

TEST_F(MeshIo, FailedWriteKeepsTheOldFile) {
  const Points x = octahedron_points();
  write_mesh(file("m.ply"), *topology_, x);
  const std::string before = read_text(file("m.ply"));
  VertexFields short_field;
  short_field.vectors.push_back({"v", x.topRows(2)});
  EXPECT_THROW(write_mesh(file("m.ply"), *topology_, x, short_field), Error);
  EXPECT_EQ(read_text(file("m.ply")), before);
  EXPECT_EQ(files_in_dir().size(), 1u);
}
