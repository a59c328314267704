#include "bendlab/core/folder_lock.hpp"

#include <fcntl.h>
#include <fmt/format.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "bendlab/core/types.hpp"

namespace bendlab {

FolderLock::FolderLock(const std::filesystem::path& folder, const std::string& what)
    : path_(folder / file_name()) {
  // The holder removes the lock file when it is done, so a process may lock a file that was
  // just unlinked; it then tries again on the new file (checked by comparing inodes).
  for (int attempt = 0; attempt < 100; ++attempt) {
    const int fd = ::open(path_.c_str(), O_RDWR | O_CREAT | O_CLOEXEC | O_NOFOLLOW, 0644);
    if (fd < 0)
      throw Error(fmt::format("cannot lock the {} '{}': {}", what, folder.string(), std::strerror(errno)));
    if (::flock(fd, LOCK_EX | LOCK_NB) != 0) {
      const int err = errno;
      ::close(fd);
      if (err == EWOULDBLOCK)
        throw Error(fmt::format("the {} '{}' is in use by another run (it holds '{}'); wait for it to end or use "
                                "another folder",
                                what, folder.string(), path_.string()));
      throw Error(fmt::format("cannot lock the {} '{}': {}", what, folder.string(), std::strerror(err)));
    }
    struct stat held {}, named {};
    if (::fstat(fd, &held) == 0 && ::stat(path_.c_str(), &named) == 0 && held.st_ino == named.st_ino &&
        held.st_dev == named.st_dev) {
      fd_ = fd;
      return;
    }
    ::close(fd);
  }
  throw Error(fmt::format("cannot lock the {} '{}': its lock file keeps changing", what, folder.string()));
}

FolderLock::~FolderLock() {
  if (fd_ < 0) return;
  ::unlink(path_.c_str());  // still locked: no other process holds this file
  ::close(fd_);
}

}  // namespace bendlab
