#include "core/output_lock.h"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>

#include "core/atomic_file.h"
#include "core/error.h"

namespace pneumo {

namespace fs = std::filesystem;

OutputFolderLock::OutputFolderLock(const std::string& dir) {
  check_creatable_folder(dir);
  std::error_code ec;
  const fs::path target = fs::absolute(fs::path(dir), ec).lexically_normal();
  std::vector<fs::path> missing;
  for (fs::path p = target; !p.empty() && !fs::exists(p, ec) && p != p.root_path(); p = p.parent_path())
    missing.push_back(p);
  for (auto it = missing.rbegin(); it != missing.rend(); ++it) {
    if (::mkdir(it->c_str(), 0777) == 0) created_.push_back(it->string());
    else if (errno != EEXIST)
      throw file_error(dir, std::string("cannot create the output folder (") + std::strerror(errno) + ")");
  }
  fd_ = ::open(target.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd_ < 0) throw file_error(dir, std::string("cannot open the output folder (") + std::strerror(errno) + ")");
  if (::flock(fd_, LOCK_EX | LOCK_NB) != 0) {
    const int e = errno;
    ::close(fd_);
    fd_ = -1;
    if (e == EWOULDBLOCK)
      throw file_error(dir, "another pneumo is writing into this folder; wait for it to finish or choose another --out");
    throw file_error(dir, std::string("cannot lock the output folder (") + std::strerror(e) + ")");
  }
}

OutputFolderLock::~OutputFolderLock() {
  if (fd_ >= 0) ::close(fd_);   // closing the last descriptor releases the lock
  for (auto it = created_.rbegin(); it != created_.rend(); ++it)
    if (::rmdir(it->c_str()) != 0) break;   // not empty: the results stay, and so do its parents
}

}  // namespace pneumo
