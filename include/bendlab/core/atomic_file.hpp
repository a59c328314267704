#pragma once
// Output files that appear whole or not at all: data goes to a temporary file beside the target,
// which is renamed onto the target by commit(). If the writer is destroyed without commit()
// (an exception, an error), the temporary file is removed and the target is untouched.
#include <filesystem>
#include <fstream>
#include <string>

namespace bendlab {

class AtomicFile {
 public:
  explicit AtomicFile(std::filesystem::path target, bool binary = false);
  ~AtomicFile();
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;

  std::ofstream& stream() { return out_; }
  /// Flushes, checks for write errors (throws bendlab::Error) and renames onto the target.
  void commit();

 private:
  std::filesystem::path target_, temp_;
  std::ofstream out_;
  bool committed_ = false;
};

}  // namespace bendlab
