#pragma once
// Progress lines for anything that may take longer than a second: steps done of total, a
// stage-specific measure (residual, voxels/s), elapsed time and ETA. Written to stderr; nothing is
// shown for work that finishes within the first second. On a terminal the line redraws in place,
// elsewhere (logs, CI) a new line is written at most every few seconds.
#include <chrono>
#include <cstdint>
#include <string>

namespace pneumo {

class Progress {
 public:
  Progress(std::string stage, int64_t total);
  ~Progress();  // finishes the line if one was shown
  /// Reports `done` of `total`; `detail` is appended (e.g. "residual 3.2e-4"). Cheap to call often.
  /// `eta_s` ≥ 0 replaces the ETA estimated from done/total (solvers estimate it from the residual).
  void update(int64_t done, const std::string& detail = "", double eta_s = -1.0);
  /// Ends the line with a final summary (only if a progress line was shown).
  void finish(const std::string& detail = "");

  /// Silences all progress output in this process (tests, --quiet).
  static void set_enabled(bool on);

 private:
  using Clock = std::chrono::steady_clock;
  void print(int64_t done, const std::string& detail, bool final, double eta_s);
  std::string stage_;
  int64_t total_, last_done_ = 0;
  Clock::time_point start_, last_print_;
  bool shown_ = false, finished_ = false, tty_;
};

}  // namespace pneumo
