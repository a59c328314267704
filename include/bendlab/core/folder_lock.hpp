#pragma once
// An advisory lock on a folder, held by one process at a time: the lock file "<folder>/.lock"
// locked with flock(). The operating system releases the lock when the process ends in any way
// (exit, crash, kill), so a lock is never left stale; the destructor also removes the file.
#include <filesystem>
#include <string>

namespace bendlab {

class FolderLock {
 public:
  /// Locks folder (which must exist) or throws bendlab::Error naming it, at once, when another
  /// process holds the lock. `what` names the folder's use in the message ("run folder").
  FolderLock(const std::filesystem::path& folder, const std::string& what);
  ~FolderLock();
  FolderLock(const FolderLock&) = delete;
  FolderLock& operator=(const FolderLock&) = delete;

  /// The lock file's name in the folder.
  static const char* file_name() { return ".lock"; }

 private:
  std::filesystem::path path_;
  int fd_ = -1;
};

}  // namespace bendlab
