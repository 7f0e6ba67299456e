// --device on every command that computes says what the scene key `device` says, in its words
// (scene_key_help), and refuses what the key refuses, with the key's allowed values and exit 2.
#include <gtest/gtest.h>

#include <string>

#include "cli_test_support.h"
#include "scene/scene.h"

using namespace pneumo;
using namespace pneumo::testing_support;

namespace {

// CLI11 wraps long help lines; compare with the whitespace folded.
std::string folded(const std::string& s) {
  std::string out;
  for (char c : s) {
    const bool space = c == ' ' || c == '\n' || c == '\t';
    if (space && (out.empty() || out.back() == ' ')) continue;
    out += space ? ' ' : c;
  }
  return out;
}

TEST(CliDeviceOption, EveryCommandHelpsWithTheSceneKeysOwnWords) {
  const std::string key = folded(scene_key_help("device"));
  ASSERT_NE(key.find("opencl:P:D"), std::string::npos) << key;
  for (const char* cmd : {"run", "simulate", "warp", "ports", "validate lame-sphere"}) {
    const CliResult r = run_pneumo(std::string(cmd) + " --help");
    ASSERT_EQ(r.code, 0) << cmd << ": " << r.err;
    EXPECT_NE(folded(r.out).find(key), std::string::npos) << cmd << "'s --device help is not the scene key's";
  }
}

TEST(CliDeviceOption, AValueTheKeyRefusesIsRefusedBeforeAnythingRuns) {
  for (const char* cmd : {"run --out /nonexistent/never", "simulate --out /nonexistent/never", "validate lame-sphere"}) {
    const CliResult r = run_pneumo(std::string(cmd) + " --device gpu");
    EXPECT_EQ(r.code, 2) << cmd;
    EXPECT_NE(r.err.find("\"opencl:P:D\""), std::string::npos) << cmd << ": " << r.err;
  }
}

}  // namespace
