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
#include "core/log.h"

namespace pneumo {

namespace fs = std::filesystem;


OutputFolderLock::OutputFolderLock(const std::string& dir) {
  check_creatable_folder(dir);
  std::error_code ec;
  const fs::path target = fs::absolute(fs::path(dir), ec).lexically_normal();
  std::vector<fs::path> missing;
  for (fs::path p = target; !p.empty() && !fs::exists(p, ec) && p != p.root_path(); p = p.parent_path())
    missing.push_back(p);
  try {
    for (auto it = missing.rbegin(); it != missing.rend(); ++it) {
      if (::mkdir(it->c_str(), 0777) == 0) created_.push_back(it->string());
      else if (errno != EEXIST)
        throw file_error(dir, std::string("cannot create the output folder (") + std::strerror(errno) + ")");
    }
    lock(dir, target);
  } catch (...) {
    release();   // no destructor runs for a throwing constructor
    throw;
  }
  remove_stale_temporaries(dir, target);
}

void OutputFolderLock::lock(const std::string& dir, const fs::path& target) {
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
    if (e == EWOULDBLOCK)
      throw file_error(dir, "another pneumo is writing into this folder; wait for it to finish or choose another --out");
    throw file_error(dir, std::string("cannot lock the output folder (") + std::strerror(e) + ")");
  }
}

void OutputFolderLock::remove_stale_temporaries(const std::string& dir, const fs::path& target) {
  // kill -9 (or a power cut) mid-write leaves AtomicFile's ".NAME.tmpPID_N.NAME" beside its target:
  // in --out, or in the folders pneumo itself fills below it (views/, flythrough/NAME/, timelapse/).
  // Only those: another --out nested deeper is another process's to clean, under its own lock.
  std::vector<fs::path> folders{target};
  std::error_code ec;
  for (const char* sub : {"views", "timelapse", "flythrough"}) {
    const fs::path p = target / sub;
    if (!fs::is_directory(p, ec)) continue;
    folders.push_back(p);
    if (std::string(sub) != "flythrough") continue;
    for (const auto& e : fs::directory_iterator(p, ec))
      if (e.is_directory(ec)) folders.push_back(e.path());
  }
  for (const fs::path& folder : folders)
    for (const auto& e : fs::directory_iterator(folder, ec)) {
      if (!e.is_regular_file(ec) || !is_atomic_temporary_name(e.path().filename().string())) continue;
      std::error_code removed;
      if (fs::remove(e.path(), removed)) ++removed_;
    }
  if (removed_ > 0)
    log::info(dir + ": removed " + std::to_string(removed_) + " temporary file(s) an interrupted run left");
}

void OutputFolderLock::release() {
  // Empty folders go while the lock is still held, so no process that takes it next finds its
  // folder removed under it.
  for (auto it = created_.rbegin(); it != created_.rend(); ++it)
    if (::rmdir(it->c_str()) != 0) break;   // not empty: the results stay, and so do its parents
  created_.clear();
  if (fd_ >= 0) ::close(fd_);   // closing the last descriptor releases the lock
  fd_ = -1;
}

OutputFolderLock::~OutputFolderLock() { release(); }

}  // namespace pneumo
