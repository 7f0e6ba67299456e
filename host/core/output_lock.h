#pragma once
// One pneumo at a time per output folder. Two processes writing into one --out mixed their
// results (a stale cavity volume reported, "metrics.json: not valid JSON"). The lock is flock(2) on
// the folder itself: held for the life of the object, released by the kernel when the process ends
// however it ends (kill -9 included), so no stale lock file is ever left to clean up.
#include <filesystem>
#include <string>
#include <vector>

namespace pneumo {

class OutputFolderLock {
 public:
  /// Creates `dir` (and missing parents) when it does not exist, then locks it. InputError (exit 2)
  /// when another process holds it, naming the folder, or when it cannot be created. Once locked,
  /// removes the temporary files an earlier process killed mid-write left (AtomicFile's names) in
  /// the folder and the ones pneumo fills below it (views/, flythrough/*/, timelapse/): no other
  /// process can be writing them now.
  explicit OutputFolderLock(const std::string& dir);

  /// How many stale temporary files the lock removed.
  int removed_temporaries() const { return removed_; }
  /// Unlocks; removes the folders it created when they are still empty (a run refused on its input
  /// leaves nothing behind).
  ~OutputFolderLock();
  OutputFolderLock(const OutputFolderLock&) = delete;
  OutputFolderLock& operator=(const OutputFolderLock&) = delete;

 private:
  void lock(const std::string& dir, const std::filesystem::path& target);
  void remove_stale_temporaries(const std::string& dir, const std::filesystem::path& target);
  void release();

  int fd_ = -1;
  int removed_ = 0;
  std::vector<std::string> created_;   // outermost first
};

}  // namespace pneumo
