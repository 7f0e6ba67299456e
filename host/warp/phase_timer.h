#pragma once
// Wall time of the warp's phases, logged at debug level (`pneumo -v warp ...`): where a slow run
// spends its time, without a profiler.
#include <chrono>
#include <cstdio>
#include <string>

#include "core/log.h"

namespace pneumo {

class PhaseTimer {
 public:
  explicit PhaseTimer(std::string what) : what_(std::move(what)) {}
  /// Ends the current phase under `name` and starts the next one.
  void lap(const char* name) {
    const auto now = std::chrono::steady_clock::now();
    char buf[64];
    std::snprintf(buf, sizeof buf, "%s %.3f s", name, std::chrono::duration<double>(now - last_).count());
    laps_ += (laps_.empty() ? "" : ", ") + std::string(buf);
    last_ = now;
  }
  ~PhaseTimer() { log::debug(what_ + ": " + laps_); }

 private:
  std::string what_, laps_;
  std::chrono::steady_clock::time_point last_ = std::chrono::steady_clock::now();
};

}  // namespace pneumo
