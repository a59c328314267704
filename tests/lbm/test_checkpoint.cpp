#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>

#include "bendlab/flow/lbm/checkpoint.hpp"

using namespace bendlab;
using namespace bendlab::lbm;
namespace fs = std::filesystem;

namespace {

LatticeConfig sheared(double tau) {
  LatticeConfig c;
  c.nx = 5;
  c.ny = 4;
  c.nz = 6;
  c.tau = tau;
  c.wall_velocity = 0.03;
  return c;
}

struct TempDir {
  fs::path path;
  TempDir() : path(fs::temp_directory_path() / ("bendlab_lbm_ckpt_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) + "_" + ::testing::UnitTest::GetInstance()->current_test_info()->name())) {
    fs::create_directories(path);
  }
  ~TempDir() { fs::remove_all(path); }
};

std::string bytes(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), {}};
}
void write_bytes(const fs::path& p, const std::string& s) {
  std::ofstream out(p, std::ios::binary);
  out << s;
}
std::string error_of(Lattice& L, const fs::path& p) {
  try {
    read_checkpoint(L, p);
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(Checkpoint, RoundTripIsBitExactAndContinuesIdentically) {
  TempDir dir;
  for (double tau : {1.0, 0.8}) {
    Lattice a(sheared(tau));
    a.initialise([](const Vec3& x) { return Vec3(0.01 * std::sin(x.y()), 0.002 * x.x(), 0.0); });
    a.run(7);  // odd parity
    const fs::path file = dir.path / "fluid.lbm";
    write_checkpoint(a, file);
    Lattice b(sheared(tau));
    read_checkpoint(b, file);
    EXPECT_EQ(b.step_count(), 7);
    ASSERT_EQ(a.raw_populations().size(), b.raw_populations().size());
    EXPECT_EQ(std::memcmp(a.raw_populations().data(), b.raw_populations().data(), a.raw_populations().size() * sizeof(double)), 0);
    a.run(3);
    b.run(3);
    EXPECT_EQ(std::memcmp(a.raw_populations().data(), b.raw_populations().data(), a.raw_populations().size() * sizeof(double)), 0);
  }
}

TEST(Checkpoint, RejectsDamagedOrForeignFiles) {
  TempDir dir;
  Lattice a(sheared(1.0));
  a.run(2);
  const fs::path good = dir.path / "good.lbm", bad = dir.path / "bad.lbm";
  write_checkpoint(a, good);
  const std::string data = bytes(good);
  Lattice b(sheared(1.0));

  write_bytes(bad, data.substr(0, data.size() - 8));
  EXPECT_NE(error_of(b, bad).find("bytes"), std::string::npos);
  write_bytes(bad, data.substr(0, 10));
  EXPECT_NE(error_of(b, bad).find("too short"), std::string::npos);
  std::string m = data;
  m[0] = 'X';
  write_bytes(bad, m);
  EXPECT_NE(error_of(b, bad).find("magic"), std::string::npos);
  m = data;
  m[8] = 9;  // version
  write_bytes(bad, m);
  EXPECT_NE(error_of(b, bad).find("version"), std::string::npos);
  EXPECT_NE(error_of(b, dir.path / "missing.lbm").find("cannot open"), std::string::npos);

  LatticeConfig other = sheared(1.0);
  other.nz = 8;
  Lattice c(other);
  EXPECT_NE(error_of(c, good).find("lattice"), std::string::npos);
  Lattice d(sheared(0.9));
  EXPECT_NE(error_of(d, good).find("does not match"), std::string::npos);
  EXPECT_EQ(b.step_count(), 0);  // untouched by the failures
  EXPECT_EQ(error_of(b, good), "");
  EXPECT_EQ(b.step_count(), 2);
}
