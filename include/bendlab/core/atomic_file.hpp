#pragma once
// Output files that appear whole or not at all: data goes to a temporary file beside the target,
// which is renamed onto the target by commit(). If the writer is destroyed without commit()
// (an exception, an error), the temporary file is removed and the target is untouched.
//
// The temporary is created exclusively (mkstemp: O_CREAT | O_EXCL under a random name
// "<target name>.tmpXXXXXX") and written through the descriptor that created it, so no file or
// symbolic link that someone else put in the folder is ever opened or followed.
#include <ext/stdio_filebuf.h>

#include <filesystem>
#include <memory>
#include <optional>
#include <ostream>
#include <string>

namespace bendlab {

/// The start of the name of every temporary file of target ("<target name>.tmp"), for finding
/// the temporaries an interrupted writer left behind.
std::string atomic_temp_prefix(const std::filesystem::path& target);

/// The name of the target whose temporary `name` is: "<target name>.tmp" followed by exactly the
/// six characters mkstemp puts for "XXXXXX" (letters A-Z, a-z and digits), else nothing. Only
/// such a name can be a temporary of AtomicFile; "a.csv.tmp", "a.csv.tmp-backup" or
/// "a.csv.tmp_mine.png" are someone else's files.
std::optional<std::string> atomic_temp_target(const std::string& name);

class AtomicFile {
 public:
  explicit AtomicFile(std::filesystem::path target, bool binary = false);
  ~AtomicFile();
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;

  std::ostream& stream() { return out_; }
  /// Flushes, checks for write errors (throws bendlab::Error) and renames onto the target.
  void commit();

 private:
  std::filesystem::path target_, temp_;
  std::unique_ptr<__gnu_cxx::stdio_filebuf<char>> buffer_;
  std::ostream out_;
  bool committed_ = false;
};

}  // namespace bendlab
