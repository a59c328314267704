// RowFile: what the writer writes the reader reads (subnormal and undefined values included), no
// result file holds a non-finite number; a resume keeps the first rows byte for byte and drops a
// half-written one.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <limits>
#include <sstream>

#include "bendlab/core/row_file.hpp"
#include "bendlab/core/types.hpp"
#include "file_test_support.hpp"

namespace fs = std::filesystem;
using bendlab::test_support::slurp;
using namespace bendlab;

namespace {
fs::path temp(const std::string& name) {
  return fs::temp_directory_path() / ("bendlab_rowfile_" + std::to_string(::getpid()) + "_" + name);
}
}  // namespace

TEST(RowFile, ReadsBackWhatItWrites) {
  const fs::path p = temp("roundtrip.csv");
  RowFile f = RowFile::create(p, "a,b,c");
  const double sub = 1.23301775164e-314;  // subnormal: std::stod would refuse it (ERANGE)
  f.append({1.0 / 3.0, -2.5e-300, sub});
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  f.append({nan, 2.0, nan});
  // Infinity is refused, and the refused row leaves nothing in the file.
  EXPECT_THROW(f.append({1.0, inf, 3.0}), Error);
  EXPECT_THROW(f.append({-inf, 2.0, 3.0}), Error);
  const std::vector<NumberRow> rows = RowFile::read_all(p, "a,b,c");
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_NEAR(rows[0][0], 1.0 / 3.0, 1e-12);
  EXPECT_NEAR(rows[0][1], -2.5e-300, 1e-311);
  EXPECT_EQ(rows[0][2], sub);  // 12 digits are all a subnormal this small holds
  // An undefined value is an empty field, read back as NaN; no "nan" or "inf" in the file.
  EXPECT_TRUE(std::isnan(rows[1][0]));
  EXPECT_EQ(rows[1][1], 2.0);
  EXPECT_TRUE(std::isnan(rows[1][2]));
  const std::string text = slurp(p);
  EXPECT_NE(text.find("\n,2,\n"), std::string::npos) << text;
  EXPECT_EQ(text.find("nan"), std::string::npos) << text;
  EXPECT_EQ(text.find("inf"), std::string::npos) << text;
  EXPECT_THROW(f.append({1.0, 2.0}), Error);
  fs::remove(p);
}

TEST(RowFile, ReadsTheNanOfOlderFilesAsUndefined) {
  const fs::path p = temp("older.csv");
  std::ofstream(p) << "a,b\nnan,1\n";
  const std::vector<NumberRow> rows = RowFile::read_all(p, "a,b");
  ASSERT_EQ(rows.size(), 1u);
  EXPECT_TRUE(std::isnan(rows[0][0]));
  fs::remove(p);
}

TEST(RowFile, ResumeKeepsTheFirstRowsAndDropsAHalfWrittenOne) {
  const fs::path p = temp("resume.csv");
  {
    RowFile f = RowFile::create(p, "t,x");
    for (int k = 0; k < 4; ++k) f.append({0.1 * k, 2.0 * k});
  }
  const std::string whole = slurp(p);
  std::ofstream(p, std::ios::app) << "0.4,8";  // a kill in the middle of a row
  EXPECT_EQ(RowFile::read_all(p, "t,x").size(), 4u);
  {
    RowFile f = RowFile::resume(p, "t,x", 2);
    EXPECT_EQ(f.rows(), 2);
    f.append({0.2, 4.0});
  }
  const std::vector<NumberRow> rows = RowFile::read_all(p, "t,x");
  ASSERT_EQ(rows.size(), 3u);
  EXPECT_EQ(rows[2][1], 4.0);
  EXPECT_EQ(slurp(p), whole.substr(0, whole.find("0.3,")));
  // Refused before any change: another header, more rows than the file holds, a bad number.
  const std::string before = slurp(p);
  EXPECT_THROW(RowFile::resume(p, "t,y", 1), Error);
  EXPECT_THROW(RowFile::resume(p, "t,x", 4), Error);
  EXPECT_EQ(slurp(p), before);
  std::ofstream(p, std::ios::app) << "0.3,1e999\n";
  EXPECT_THROW(RowFile::read_all(p, "t,x"), Error);
  fs::remove(p);
}
