#pragma once
// Writes that never leave a file looking complete when they were not: data goes to a temporary
// name beside the target (same folder, so rename is atomic), and only commit() flushes it to disk
// and renames it into place. If the writer throws or is interrupted, the destructor removes the
// temporary file.
#include <string>

namespace pneumo {

class AtomicFile {
 public:
  explicit AtomicFile(std::string target);
  ~AtomicFile();
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;

  /// Where to write. Keeps the target's extensions (".nii.gz") so libraries that choose the
  /// format by name still do the right thing.
  const std::string& temp_path() const { return temp_; }
  const std::string& target_path() const { return target_; }
  /// Renames the temporary file to the target; throws if that fails.
  void commit();

 private:
  std::string target_, temp_;
  bool committed_ = false;
};

/// Whether a file name is one AtomicFile gives its temporary files (".NAME.tmpPID_N.NAME"): what a
/// process killed mid-write leaves, for the next one into the folder to remove (output_lock.h).
bool is_atomic_temporary_name(const std::string& file_name);

/// Writes `text` to `path` atomically.
void write_text_file_atomic(const std::string& path, const std::string& text);

/// Throws InputError when the folder that would hold `path` does not exist or is not writable.
void check_writable_target(const std::string& path);

/// Throws InputError when the output folder `dir` could not be written to: it exists and is not a
/// writable folder, or it does not exist and its nearest existing ancestor is not a writable
/// folder. Creates nothing, so a run refused later leaves no empty folder behind.
void check_creatable_folder(const std::string& dir);

}  // namespace pneumo
