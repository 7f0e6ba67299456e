#pragma once
// Every file pneumo reads is a regular file, checked before the first byte is read. A FIFO's
// open() waits for a writer (forever, if none comes), a character device such as /dev/zero never
// ends, and neither has a size to check a cap or a header against; a symbolic link is followed to
// what it names. The check is race-safe where pneumo opens the file itself: stat() refuses what is
// not regular without opening it, then the open is non-blocking (O_NONBLOCK: a FIFO's open
// returns at once) and fstat() checks the descriptor that is read, so a file swapped for a FIFO
// between the two is still refused and never waited on. Files a library opens by name (teem's
// NRRD data, GDCM's slices) are checked just before the library opens them.
#include <cstdint>
#include <cstdio>
#include <string>

namespace pneumo {

/// What a path names, following symbolic links; found with lstat() and stat(), never by opening it.
enum class FileKind { Regular, Folder, Missing, DanglingLink, LinkLoop, Fifo, Socket, Device, Unreadable, Other };

struct FileProbe {
  FileKind kind = FileKind::Missing;
  int error = 0;            // errno of a stat() that failed (Unreadable)
  std::string link_target;  // a dangling link's or a loop's target as written
  uint64_t size = 0;        // Regular only
};

/// The kind of `path` (a dangling link is told from a missing file): never opens, never blocks.
FileProbe probe_file(const std::string& path);

/// "is a FIFO (named pipe), not a regular file: <advice>", "is a symbolic link to ..., which does not
/// exist: fix or remove the link", ...: the rest of a one-line refusal after "<what> ". `advice` is
/// what to do with what is not a file (a FIFO, a socket, a device). Empty for a regular file.
std::string file_kind_problem(const FileProbe& probe,
                              const std::string& advice = "save the data as a file and give that");

/// A regular file open for reading (the descriptor closed on destruction).
class InputFile {
 public:
  /// Opens `path` as the header above says, or throws InputError "<reported>: <what> ..." (reported
  /// defaults to path): missing, a folder, a FIFO, a socket, a device, a dangling link, unreadable.
  explicit InputFile(const std::string& path, const std::string& what = "the file", const std::string& reported = "");
  ~InputFile();
  InputFile(const InputFile&) = delete;
  InputFile& operator=(const InputFile&) = delete;

  int fd() const { return fd_; }
  /// The size fstat() gave at open.
  uint64_t size() const { return size_; }
  /// The descriptor as a stdio stream, now the caller's to fclose (this object lets it go).
  std::FILE* release_to_stdio();
  /// The descriptor, now the caller's to close.
  int release();

 private:
  int fd_ = -1;
  uint64_t size_ = 0;
};

/// The check alone, for a file a library then opens by name: its size, or InputError as above.
uint64_t require_regular_file(const std::string& path, const std::string& what = "the file",
                              const std::string& reported = "");

/// The whole file, at most `max_bytes`: refused before reading when fstat() says it is larger, and
/// counted while reading, so a file that grows meanwhile is refused too (the cap always holds).
/// `limit_words` ends the refusal, e.g. "16 MB; scenes are a few kB".
std::string read_input_file(const std::string& path, uint64_t max_bytes, const std::string& what,
                            const std::string& limit_words);

}  // namespace pneumo
