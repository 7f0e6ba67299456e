// kill -9 during `pneumo run`: whatever moment it
// lands, every file under a final name is complete (JSON parses, NIfTI reads whole, PNG ends in its
// IEND chunk), the lock dies with the process, and the next run into the folder removes the
// temporary files the killed one left. Killed at four moments of a run.
#include <gtest/gtest.h>

#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>

#include <nlohmann/json.hpp>

#include "cli_test_support.h"
#include "io/volume_io.h"
#include "io_test_support.h"
#include "springs_support.h"
#include "tiny_case_support.h"

namespace pneumo {
namespace {

using namespace testing_support;
namespace fs = std::filesystem;

bool temporary_name(const std::string& f) { return f.size() > 1 && f[0] == '.' && f.find(".tmp") != std::string::npos; }

/// Whether process `pid` is gone (or a zombie nobody has reaped yet: it holds no files).
bool gone(pid_t pid) {
  std::ifstream stat("/proc/" + std::to_string(pid) + "/stat");
  std::string line;
  if (!std::getline(stat, line)) return true;
  const std::size_t close = line.rfind(')');
  return close != std::string::npos && close + 2 < line.size() && line[close + 2] == 'Z';
}

/// Every file under a final name is whole; returns how many were checked.
int check_complete(const fs::path& out) {
  int checked = 0;
  for (const auto& e : fs::recursive_directory_iterator(out)) {
    if (!e.is_regular_file()) continue;
    const std::string name = e.path().filename().string(), path = e.path().string();
    if (temporary_name(name)) continue;
    ++checked;
    SCOPED_TRACE(path);
    if (name.size() > 5 && name.substr(name.size() - 5) == ".json") {
      EXPECT_FALSE(nlohmann::json::parse(slurp(path), nullptr, false).is_discarded()) << "incomplete JSON";
    } else if (name.size() > 7 && name.substr(name.size() - 7) == ".nii.gz") {
      EXPECT_NO_THROW(read_volume(path)) << "incomplete NIfTI";
    } else if (name.size() > 4 && name.substr(name.size() - 4) == ".png") {
      const std::string bytes = slurp(path);
      EXPECT_TRUE(bytes.size() > 12 && bytes.compare(bytes.size() - 8, 4, "IEND") == 0) << "incomplete PNG";
    }
  }
  return checked;
}

TEST(KillDuringRun, WhatItLeavesIsWholeOrAbsentAndTheNextRunCleansUp) {
  // The tiny case made slow enough to be caught at work: the explicit solver over a 2 s ramp, and
  // views large enough that rendering and writing them take a while. Uninterrupted runs first
  // measure how long a run takes here; the kills land at fractions of it, so they fall in the
  // solve, in the warp and in the writing however fast the machine is. The shorter of two runs is
  // the measure: the first may be slowed by what it warms (kernel and file caches), and on a busy
  // machine a slow measure would put the last kills after the killed runs had finished.
  ScratchDir d;
  nlohmann::json s = tiny_case_scene_json();
  s["material"] = springs_material_json();   // the explicit scheme takes the springs only
  s["solver"] = {{"method", "explicit"}};
  s["load"]["ramp_ms"] = 2000;
  s["render"]["width"] = 480;
  s["render"]["height"] = 360;
  const std::string scene = write_tiny_case(d, s);
  double whole_run_s = 1e30;
  for (int run = 0; run < 2; ++run) {
    const auto t0 = std::chrono::steady_clock::now();
    ASSERT_EQ(run_pneumo("-q run " + scene + " --out " + d.file("control") + " --force").code, 0);
    whole_run_s = std::min(whole_run_s, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  }
  std::printf("an uninterrupted run: %.2f s (the shorter of two)\n", whole_run_s);
  int index = 0, killed_running = 0;
  for (const double fraction : {0.25, 0.5, 0.7, 0.85}) {
    // A run that finished before its kill tests nothing: the machine got faster than when it was
    // measured (a job beside it ended). Then the measure shrinks by a third and the kill is tried
    // again, up to three times, so the kills still land in the work on a machine whose load changes.
    for (int attempt = 0; attempt < 3; ++attempt) {
      const double after_s = fraction * whole_run_s;
      SCOPED_TRACE("killed after " + std::to_string(after_s) + " s");
      const std::string out = d.file("out" + std::to_string(index++)), pid_file = d.file("pid");
      const std::string start = std::string(PNEUMO_CLI_PATH) + " -q run " + scene + " --out " + out +
                                " >/dev/null 2>&1 </dev/null & echo $! > " + pid_file;
      ASSERT_EQ(std::system(start.c_str()), 0);
      const pid_t pid = static_cast<pid_t>(std::stol(slurp(pid_file)));
      std::this_thread::sleep_for(std::chrono::duration<double>(after_s));
      const bool running = !gone(pid);
      ::kill(pid, SIGKILL);
      for (int i = 0; i < 200 && !gone(pid); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(50));
      ASSERT_TRUE(gone(pid));
      const int whole = fs::exists(out) ? check_complete(out) : 0;
      const CliResult again = run_pneumo("-q run " + scene + " --out " + out + " --force");
      ASSERT_EQ(again.code, 0) << again.err;
      for (const auto& e : fs::recursive_directory_iterator(out))
        EXPECT_FALSE(temporary_name(e.path().filename().string())) << "left: " << e.path();
      std::printf("killed after %.1f s%s: %d whole files left, none partial; the next run completed\n", after_s,
                  running ? "" : " (it had finished)", whole);
      if (running) {
        ++killed_running;
        break;
      }
      whole_run_s *= 2.0 / 3.0;
    }
  }
  // Runs that had finished before the kill test nothing: most must have been caught at work.
  EXPECT_GE(killed_running, 3) << "too few runs were still running when killed";
}

}  // namespace
}  // namespace pneumo
