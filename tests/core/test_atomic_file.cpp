// Output files: written whole through an exclusive temporary, or not at all.
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

#include <csignal>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>
#include <set>
#include <string>
#include <vector>

#include "bendlab/core/atomic_file.hpp"
#include "bendlab/core/types.hpp"

namespace fs = std::filesystem;
using namespace bendlab;

namespace {

class AtomicFileTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir = fs::temp_directory_path() / ("bendlab_atomic_" + std::to_string(::getpid()) + "_" +
                                       ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir);
    fs::create_directories(dir);
  }
  void TearDown() override { fs::remove_all(dir); }
  static std::string slurp(const fs::path& p) {
    std::ifstream in(p);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
  }
  // The names in dir other than `keep`.
  std::vector<std::string> others(const std::set<std::string>& keep) const {
    std::vector<std::string> names;
    for (const auto& e : fs::directory_iterator(dir))
      if (!keep.count(e.path().filename().string())) names.push_back(e.path().filename().string());
    return names;
  }
  fs::path dir;
};

}  // namespace

TEST_F(AtomicFileTest, APlantedSymbolicLinkIsNeverFollowed) {
  // The name the temporary had before (target + ".tmp" + the process id), and the bare prefix,
  // as links to a file that must stay untouched.
  const fs::path victim = dir / "victim", target = dir / "out.off";
  std::ofstream(victim) << "precious";
  for (const std::string& name : {"out.off.tmp" + std::to_string(::getpid()), std::string("out.off.tmp")})
    fs::create_symlink(victim, dir / name);
  {
    AtomicFile f(target);
    f.stream() << "mesh";
    f.commit();
  }
  EXPECT_EQ(slurp(victim), "precious");
  EXPECT_EQ(slurp(target), "mesh");
  EXPECT_TRUE(fs::is_symlink(dir / ("out.off.tmp" + std::to_string(::getpid()))));
  EXPECT_EQ(others({"victim", "out.off", "out.off.tmp", "out.off.tmp" + std::to_string(::getpid())}).size(), 0u);
}

TEST_F(AtomicFileTest, TheTemporaryLiesBesideTheTargetAndGoesWithoutCommit) {
  const fs::path target = dir / "a.csv";
  {
    AtomicFile f(target);
    f.stream() << "x";
    const std::vector<std::string> names = others({});
    ASSERT_EQ(names.size(), 1u);
    EXPECT_EQ(names[0].rfind(atomic_temp_prefix(target), 0), 0u) << names[0];
  }
  EXPECT_TRUE(others({}).empty());
}

TEST_F(AtomicFileTest, OutputsGetTheUsualPermissions) {
  const mode_t mask = ::umask(022);
  {
    AtomicFile f(dir / "p.json");
    f.stream() << "{}";
    f.commit();
  }
  ::umask(mask);
  EXPECT_EQ(fs::status(dir / "p.json").permissions() & fs::perms::all,
            fs::perms::owner_read | fs::perms::owner_write | fs::perms::group_read | fs::perms::others_read);
}

TEST_F(AtomicFileTest, AWriteBeyondTheFileSizeLimitIsAnErrorAndLeavesNothing) {
  // As under `ulimit -f`, with SIGXFSZ ignored (as the command line does): the write fails.
  const auto old_handler = std::signal(SIGXFSZ, SIG_IGN);
  struct rlimit old {};
  ASSERT_EQ(::getrlimit(RLIMIT_FSIZE, &old), 0);
  struct rlimit small = old;
  small.rlim_cur = 4096;
  ASSERT_EQ(::setrlimit(RLIMIT_FSIZE, &small), 0);
  const fs::path target = dir / "big.vtp";
  std::string message;
  try {
    AtomicFile f(target);
    f.stream() << std::string(100000, 'x');
    f.commit();
  } catch (const Error& e) {
    message = e.what();
  }
  ::setrlimit(RLIMIT_FSIZE, &old);
  std::signal(SIGXFSZ, old_handler);
  EXPECT_NE(message.find("big.vtp"), std::string::npos) << message;
  EXPECT_TRUE(others({}).empty());
}

TEST_F(AtomicFileTest, OnlyMkstempsNamesAreTakenForTemporaries) {
  // The name a temporary really has is recognised, with its target.
  const fs::path target = dir / "timeseries.csv";
  {
    AtomicFile f(target);
    const std::vector<std::string> names = others({});
    ASSERT_EQ(names.size(), 1u);
    EXPECT_EQ(atomic_temp_target(names[0]), std::optional<std::string>("timeseries.csv")) << names[0];
  }
  EXPECT_EQ(atomic_temp_target("snapshot_00001.vtp.tmpAb3dEf"), std::optional<std::string>("snapshot_00001.vtp"));
  EXPECT_EQ(atomic_temp_target("a.tmp.tmp09AZaz"), std::optional<std::string>("a.tmp"));
  // Anything else after ".tmp" is no temporary of AtomicFile: a user's file.
  for (const char* name : {"timeseries.csv.tmp-backup-2024", "summary.json.tmp.mine", "checkpoint.json.tmp",
                           "D_theta.png.tmp_by_user.png", "timing.json.tmp12345", "shapes.pvd.tmpABCDEFG",
                           "x.tmpab-def", ".tmpAbCdEf", "timeseries.csv", "tmpAbCdEf"})
    EXPECT_EQ(atomic_temp_target(name), std::nullopt) << name;
}
