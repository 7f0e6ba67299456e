// --backend on every command that draws says the same thing and refuses what the renderer does not
// know, when the command line is read: exit 2 with the allowed values, before any scene is read.
#include <gtest/gtest.h>

#include <string>

#include "cli_test_support.h"

using namespace pneumo::testing_support;

TEST(CliGlBackendOption, EveryCommandThatDrawsOffersTheSameBackEnds) {
  for (const char* cmd : {"run", "render", "serve", "ports"}) {
    const CliResult r = run_pneumo(std::string(cmd) + " --help");
    ASSERT_EQ(r.code, 0) << cmd << ": " << r.err;
    EXPECT_NE(r.out.find("auto, egl-device, egl-surfaceless, osmesa"), std::string::npos) << cmd << ": " << r.out;
  }
}

TEST(CliGlBackendOption, AnUnknownBackEndIsRefusedBeforeAnythingRuns) {
  for (const char* cmd : {"run /nonexistent/scene.json --out /nonexistent/never", "render /nonexistent/scene.json",
                          "ports /nonexistent/scene.json", "serve"}) {
    const CliResult r = run_pneumo(std::string(cmd) + " --backend vulkan");
    EXPECT_EQ(r.code, 2) << cmd;
    EXPECT_NE(r.err.find("egl-surfaceless"), std::string::npos) << cmd << ": " << r.err;
    EXPECT_EQ(r.err.find("nonexistent"), std::string::npos) << cmd << ": read a scene before refusing: " << r.err;
  }
}
