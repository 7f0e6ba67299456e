#include "core/output_lock.h"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cctype>
#include <cerrno>
#include <cstring>
#include <filesystem>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/log.h"

namespace pneumo {

namespace fs = std::filesystem;

namespace {

/// ".NAME.tmpPID_N.NAME", the temporary names AtomicFile gives (atomic_file.cpp).
bool is_atomic_temporary(const std::string& f) {
  if (f.size() < 8 || f[0] != '.') return false;
  const std::size_t tmp = f.find(".tmp", 1);
  if (tmp == std::string::npos) return false;
  const std::string name = f.substr(1, tmp - 1);
  std::size_t i = tmp + 4;
  const std::size_t pid_start = i;
  while (i < f.size() && std::isdigit(static_cast<unsigned char>(f[i]))) ++i;
  if (i == pid_start || i >= f.size() || f[i] != '_') return false;
  const std::size_t n_start = ++i;
  while (i < f.size() && std::isdigit(static_cast<unsigned char>(f[i]))) ++i;
  return i > n_start && f.compare(i, std::string::npos, "." + name) == 0;
}

}  // namespace

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
  // A process that has just ended (kill -9 included) can hold the lock a few milliseconds longer:
  // the kernel releases it when its last reference to the folder goes, which may trail the exit.
  // Half a second of retries lets a command started right after it in; a process that is still
  // running is refused after that.
  int rc = ::flock(fd_, LOCK_EX | LOCK_NB);
  for (int tries = 0; rc != 0 && errno == EWOULDBLOCK && tries < 25; ++tries) {
    ::usleep(20000);
    rc = ::flock(fd_, LOCK_EX | LOCK_NB);
  }
  if (rc != 0) {
    const int e = errno;
    ::close(fd_);
    fd_ = -1;
    if (e == EWOULDBLOCK)
      throw file_error(dir, "another pneumo is writing into this folder; wait for it to finish or choose another --out");
    throw file_error(dir, std::string("cannot lock the output folder (") + std::strerror(e) + ")");
  }
  // kill -9 (or a power cut) mid-write leaves AtomicFile's ".NAME.tmpPID_N.NAME" beside its target,
  // in --out or a folder below it (views/, flythrough/NAME/): none is being written now.
  for (auto it = fs::recursive_directory_iterator(target, fs::directory_options::skip_permission_denied, ec);
       !ec && it != fs::recursive_directory_iterator(); it.increment(ec)) {
    if (it.depth() > 3) it.disable_recursion_pending();
    if (!it->is_regular_file(ec) || !is_atomic_temporary(it->path().filename().string())) continue;
    std::error_code removed;
    if (fs::remove(it->path(), removed)) ++removed_;
  }
  if (removed_ > 0)
    log::info(dir + ": removed " + std::to_string(removed_) + " temporary file(s) an interrupted run left");
}

OutputFolderLock::~OutputFolderLock() {
  if (fd_ >= 0) ::close(fd_);   // closing the last descriptor releases the lock
  for (auto it = created_.rbegin(); it != created_.rend(); ++it)
    if (::rmdir(it->c_str()) != 0) break;   // not empty: the results stay, and so do its parents
}

}  // namespace pneumo
