#include "core/input_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <vector>

#include "core/error.h"

namespace pneumo {

namespace {

FileKind kind_of_mode(mode_t mode) {
  if (S_ISREG(mode)) return FileKind::Regular;
  if (S_ISDIR(mode)) return FileKind::Folder;
  if (S_ISFIFO(mode)) return FileKind::Fifo;
  if (S_ISSOCK(mode)) return FileKind::Socket;
  if (S_ISCHR(mode) || S_ISBLK(mode)) return FileKind::Device;
  return FileKind::Other;
}

std::string link_target(const std::string& path) {
  std::vector<char> buf(4096);
  const ssize_t n = ::readlink(path.c_str(), buf.data(), buf.size());
  return n > 0 ? std::string(buf.data(), std::size_t(n)) : std::string();
}

/// The kind of an entry whose stat() failed with `error`: lstat() tells a link that leads nowhere.
FileProbe probe_failed_stat(const std::string& path, int error) {
  FileProbe p;
  struct stat own {};
  const bool is_link = ::lstat(path.c_str(), &own) == 0 && S_ISLNK(own.st_mode);
  if (is_link && error == ENOENT) p.kind = FileKind::DanglingLink;
  else if (is_link && error == ELOOP) p.kind = FileKind::LinkLoop;
  else if (error == ENOENT) p.kind = FileKind::Missing;
  else p.kind = FileKind::Unreadable;
  if (is_link) p.link_target = link_target(path);
  p.error = error;
  return p;
}

[[noreturn]] void refuse(const std::string& reported, const std::string& what, const FileProbe& p) {
  throw file_error(reported, what + " " + file_kind_problem(p));
}

/// The probe of an open descriptor (fstat): what is really read, whatever the path names now.
FileProbe probe_descriptor(int fd) {
  FileProbe p;
  struct stat st {};
  if (::fstat(fd, &st) != 0) {
    p.kind = FileKind::Unreadable;
    p.error = errno;
    return p;
  }
  p.kind = kind_of_mode(st.st_mode);
  p.size = p.kind == FileKind::Regular ? uint64_t(st.st_size) : 0;
  return p;
}

}  // namespace

FileProbe probe_file(const std::string& path) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) return probe_failed_stat(path, errno);
  FileProbe p;
  p.kind = kind_of_mode(st.st_mode);
  if (p.kind == FileKind::Regular) p.size = uint64_t(st.st_size);
  return p;
}

std::string file_kind_problem(const FileProbe& p, const std::string& advice) {
  const std::string instead = ", not a regular file: " + advice;
  switch (p.kind) {
    case FileKind::Regular: return "";
    case FileKind::Folder: return "is a folder, not a file";
    case FileKind::Missing: return "does not exist";
    case FileKind::DanglingLink:
      return "is a symbolic link to \"" + p.link_target + "\", which does not exist: fix or remove the link";
    case FileKind::LinkLoop:
      return "is a symbolic link to \"" + p.link_target + "\" that leads back to itself: fix or remove the link";
    case FileKind::Fifo: return "is a FIFO (named pipe)" + instead;
    case FileKind::Socket: return "is a socket" + instead;
    case FileKind::Device: return "is a device" + instead;
    case FileKind::Unreadable: return std::string("cannot be read: ") + std::strerror(p.error);
    case FileKind::Other: break;
  }
  return "is not a regular file: " + advice;
}

InputFile::InputFile(const std::string& path, const std::string& what, const std::string& reported) {
  const std::string& name = reported.empty() ? path : reported;
  const FileProbe before = probe_file(path);
  if (before.kind != FileKind::Regular) refuse(name, what, before);
  fd_ = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_NOCTTY | O_CLOEXEC);
  if (fd_ < 0) {
    const int error = errno;
    refuse(name, what, error == ENOENT ? probe_failed_stat(path, error) : FileProbe{FileKind::Unreadable, error, {}, 0});
  }
  const FileProbe opened = probe_descriptor(fd_);
  if (opened.kind != FileKind::Regular) {
    ::close(fd_);
    fd_ = -1;
    refuse(name, what, opened);
  }
  size_ = opened.size;
  // Reads of a regular file never block; the flag is cleared so that stdio and zlib see the
  // descriptor they expect.
  ::fcntl(fd_, F_SETFL, ::fcntl(fd_, F_GETFL) & ~O_NONBLOCK);
}

InputFile::~InputFile() {
  if (fd_ >= 0) ::close(fd_);
}

std::FILE* InputFile::release_to_stdio() {
  std::FILE* f = ::fdopen(fd_, "rb");
  if (!f) throw std::runtime_error(std::string("fdopen failed: ") + std::strerror(errno));
  fd_ = -1;
  return f;
}

int InputFile::release() {
  const int fd = fd_;
  fd_ = -1;
  return fd;
}

uint64_t require_regular_file(const std::string& path, const std::string& what, const std::string& reported) {
  return InputFile(path, what, reported).size();
}

std::string read_input_file(const std::string& path, uint64_t max_bytes, const std::string& what,
                            const std::string& limit_words) {
  InputFile f(path, what);
  const auto too_large = [&](const std::string& size) {
    return file_error(path, what + " is " + size + " bytes; at most " + std::to_string(max_bytes) + " are read (" +
                                limit_words + ")");
  };
  if (f.size() > max_bytes) throw too_large(std::to_string(f.size()));
  std::string bytes;
  bytes.reserve(std::size_t(f.size()));
  char chunk[1 << 16];
  for (;;) {
    const ssize_t got = ::read(f.fd(), chunk, sizeof chunk);
    if (got < 0 && errno == EINTR) continue;
    if (got < 0) throw file_error(path, "cannot read " + what + ": " + std::strerror(errno));
    if (got == 0) return bytes;
    if (bytes.size() + std::size_t(got) > max_bytes) throw too_large("more than " + std::to_string(max_bytes));
    bytes.append(chunk, std::size_t(got));
  }
}

}  // namespace pneumo
