// Helper programs start from an argument vector: no shell ever sees a file name.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "bendlab/core/helper_program.hpp"
#include "bendlab/core/types.hpp"

namespace fs = std::filesystem;
using namespace bendlab;

TEST(HelperProgram, ReturnsTheExitStatus) {
  EXPECT_EQ(run_helper_program({"/bin/true"}), 0);
  EXPECT_EQ(run_helper_program({"/bin/false"}), 1);
}

TEST(HelperProgram, ArgumentsReachTheProgramVerbatim) {
  // A name that a shell would split, expand or execute: quotes, spaces, `;`, `$( )`.
  const fs::path dir = fs::temp_directory_path() / "bendlab_helper_program_test";
  fs::remove_all(dir);
  fs::create_directories(dir);
  const fs::path odd = dir / "it's a; $(touch pwned) name";
  EXPECT_EQ(run_helper_program({"/usr/bin/touch", odd.string()}), 0);
  EXPECT_TRUE(fs::is_regular_file(odd));
  EXPECT_FALSE(fs::exists(dir / "pwned"));
  EXPECT_FALSE(fs::exists("pwned"));
  fs::remove_all(dir);
}

TEST(HelperProgram, AProgramThatCannotStartIsAnError) {
  try {
    run_helper_program({"/nonexistent/program", "x"});
    FAIL() << "expected bendlab::Error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/program"), std::string::npos) << e.what();
  }
  EXPECT_THROW(run_helper_program({}), Error);
}

TEST(HelperProgram, AnExplicitScriptPathWins) {
  EXPECT_EQ(find_helper_script("plot_shear.py", "/some/where/mine.py"), fs::path("/some/where/mine.py"));
  EXPECT_TRUE(find_helper_script("no_such_script_anywhere.py").empty());
}
