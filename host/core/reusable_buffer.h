#pragma once
// Working memory kept from one call to the next. Fresh memory costs a page fault per page on its first
// touch: on the VMs here a few tenths of a second per GB, and a few seconds per GB where the host has
// taken the pages back (free page reporting returns memory left free for ~2 s). A job repeated on data
// of one size (a time-lapse's frames, a benchmark's repetitions) faults its working memory in once.
#include <cstddef>
#include <cstdlib>
#include <memory>
#include <new>

namespace pneumo {

class ReusableBuffer {
 public:
  /// At least `bytes`, aligned to 64 bytes, contents undefined; reallocated only when it grows.
  /// Throws std::bad_alloc.
  void* reserve(std::size_t bytes) {
    if (bytes > bytes_) {
      memory_.reset();
      bytes_ = 0;
      const std::size_t rounded = (bytes + 63) / 64 * 64;
      void* p = std::aligned_alloc(64, rounded);
      if (!p) throw std::bad_alloc();
      memory_.reset(p);
      bytes_ = rounded;
    }
    return memory_.get();
  }

 private:
  struct Free {
    void operator()(void* p) const { std::free(p); }
  };
  std::unique_ptr<void, Free> memory_;
  std::size_t bytes_ = 0;
};

}  // namespace pneumo
