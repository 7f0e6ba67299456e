#include "core/atomic_file.h"

#include <fcntl.h>
#include <unistd.h>

#include <atomic>
#include <cctype>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <stdexcept>

#include "core/error.h"

namespace fs = std::filesystem;

namespace pneumo {

AtomicFile::AtomicFile(std::string target) : target_(std::move(target)) {
  static std::atomic<unsigned> counter{0};
  const fs::path t(target_);
  // ".<name>.tmp<pid>_<n>.<name>": hidden, unique per process and call, and still ending in the
  // target's own extensions.
  const std::string name = t.filename().string();
  const std::string tmp_name =
      "." + name + ".tmp" + std::to_string(::getpid()) + "_" + std::to_string(counter++) + "." + name;
  temp_ = (t.parent_path() / tmp_name).string();
}

AtomicFile::~AtomicFile() {
  if (!committed_) std::remove(temp_.c_str());
}

void AtomicFile::commit() {
  // On the disk before it takes the target's name: after a crash of the machine the name holds the
  // old file or the whole new one, never a new name over blocks not yet written.
  const int fd = ::open(temp_.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0 || ::fsync(fd) != 0) {
    const int e = errno;
    if (fd >= 0) ::close(fd);
    throw std::runtime_error("cannot flush " + temp_ + " to disk: " + std::strerror(e));
  }
  ::close(fd);
  if (std::rename(temp_.c_str(), target_.c_str()) != 0)
    throw std::runtime_error("cannot rename " + temp_ + " to " + target_ + ": " + std::strerror(errno));
  committed_ = true;
}

bool is_atomic_temporary_name(const std::string& f) {
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

void check_writable_target(const std::string& path) {
  fs::path dir = fs::path(path).parent_path();
  if (dir.empty()) dir = ".";
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) throw file_error(path, "folder " + dir.string() + " does not exist");
  if (::access(dir.c_str(), W_OK) != 0) throw file_error(path, "folder " + dir.string() + " is not writable");
}

void check_creatable_folder(const std::string& dir) {
  std::error_code ec;
  fs::path p = fs::absolute(fs::path(dir), ec);
  if (ec) throw file_error(dir, "not a usable folder name (" + ec.message() + ")");
  if (fs::exists(p, ec)) {
    if (!fs::is_directory(p, ec)) throw file_error(dir, "exists and is not a folder");
    if (::access(p.c_str(), W_OK) != 0) throw file_error(dir, "the output folder is not writable");
    return;
  }
  fs::path ancestor = p.parent_path();
  while (!ancestor.empty() && !fs::exists(ancestor, ec) && ancestor != ancestor.root_path())
    ancestor = ancestor.parent_path();
  if (!fs::is_directory(ancestor, ec))
    throw file_error(dir, "cannot create the output folder: " + ancestor.string() + " is not a folder");
  if (::access(ancestor.c_str(), W_OK) != 0)
    throw file_error(dir, "cannot create the output folder: " + ancestor.string() + " is not writable");
}

void write_text_file_atomic(const std::string& path, const std::string& text) {
  check_writable_target(path);
  AtomicFile f(path);
  {
    std::ofstream os(f.temp_path(), std::ios::binary);
    os << text;
    os.flush();
    if (!os) throw std::runtime_error("cannot write " + f.temp_path() + ": " + std::strerror(errno));
  }
  f.commit();
}

}  // namespace pneumo
