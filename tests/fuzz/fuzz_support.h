#pragma once
// What the fuzz targets share: each input goes to a file (the readers take paths, as users give them),
// a problem reported as an InputError is the expected answer to a hostile file, and anything else
// (another exception, a crash, a sanitizer report) is a bug for libFuzzer to keep.
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <fstream>
#include <string>

#include "core/error.h"
#include "core/log.h"
#include "core/progress.h"

namespace pneumo::fuzz {

/// A private scratch folder per process (libFuzzer's -jobs/-workers run processes side by side).
inline const std::string& scratch_dir() {
  static const std::string dir = [] {
    const char* base = std::getenv("TMPDIR");
    std::filesystem::path p = std::filesystem::path(base && *base ? base : "/tmp") /
                              ("pneumo-fuzz-" + std::to_string(::getpid()));
    std::filesystem::create_directories(p);
    return p.string();
  }();
  return dir;
}

/// Writes the input under `name` in the scratch folder and returns its path.
inline std::string write_input(const std::string& name, const uint8_t* data, size_t size) {
  const std::string path = scratch_dir() + "/" + name;
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(data), std::streamsize(size));
  return path;
}

/// Silences progress lines and warnings (millions of runs), once.
inline void quiet() {
  static const bool done = [] {
    Progress::set_enabled(false);
    log::set_level(log::Level::Quiet);
    return true;
  }();
  (void)done;
}

/// Runs `body`; an InputError is the right answer, any other exception is reported and aborts so
/// that libFuzzer records the input as a crash.
template <class F>
int expect_only_input_errors(F&& body) {
  try {
    body();
  } catch (const InputError&) {
  } catch (const std::exception& e) {
    std::fprintf(stderr, "not an InputError: %s\n", e.what());
    std::abort();
  }
  return 0;
}

}  // namespace pneumo::fuzz
