// One run per folder: the lock is held by one owner at a time and released with it.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <optional>

#include "bendlab/core/folder_lock.hpp"
#include "bendlab/core/types.hpp"

namespace fs = std::filesystem;
using namespace bendlab;

TEST(FolderLock, ASecondOwnerIsRefusedUntilTheFirstIsDone) {
  const fs::path dir = fs::temp_directory_path() / ("bendlab_lock_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  {
    std::optional<FolderLock> first;
    first.emplace(dir, "run folder");
    EXPECT_TRUE(fs::exists(dir / FolderLock::file_name()));
    try {
      FolderLock second(dir, "run folder");
      ADD_FAILURE() << "two owners of one folder";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find("in use by another run"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(dir.string()), std::string::npos) << e.what();
    }
    first.reset();
    EXPECT_FALSE(fs::exists(dir / FolderLock::file_name()));  // removed by its owner
    FolderLock third(dir, "run folder");                       // free again
  }
  // A folder that does not exist cannot be locked, and the message says why.
  EXPECT_THROW(FolderLock(dir / "missing", "run folder"), Error);
  fs::remove_all(dir);
}
