#pragma once
// Wall-clock seconds for progress lines, metrics and benchmarks (steady: never jumps with the system clock).
#include <chrono>

namespace pneumo {

inline double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace pneumo
