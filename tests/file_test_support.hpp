#pragma once
// Whole-file reads and writes for the tests that check what a run wrote or corrupt it on purpose.
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace bendlab::test_support {

/// The bytes of a file ("" if it cannot be opened).
inline std::string slurp(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

/// Replaces a file's bytes by `text`.
inline void spit(const std::filesystem::path& p, const std::string& text) {
  std::ofstream(p, std::ios::binary) << text;
}

}  // namespace bendlab::test_support
