// `pneumo roles SCENE [--png FILE] [--at X,Y,Z]` as a user meets it: a summary per role, a PNG, and
// exit code 2 with a one-line message for bad input.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "cli_test_support.h"

using pneumo::testing_support::ScratchDir;

namespace {

using pneumo::testing_support::CliResult;
using pneumo::testing_support::run_pneumo;
using pneumo::testing_support::slurp;

}  // namespace

TEST(RolesCli, SummarisesAndDrawsThePhantom) {
  ScratchDir dir;
  const std::string c = dir.file("case");
  ASSERT_EQ(run_pneumo("-q phantom --size small --out " + c).code, 0);
  const std::string png = dir.file("roles.png");
  const CliResult r = run_pneumo("roles " + c + "/scene.json --png " + png + " --at 0,10,-20");
  ASSERT_EQ(r.code, 0) << r.err;
  for (const char* word : {"wall", "viscera", "fixed", "other", "96 x 96 x 96", "padding", "ml"})
    EXPECT_NE(r.out.find(word), std::string::npos) << word << " missing from:\n" << r.out;
  ASSERT_TRUE(std::filesystem::exists(png));
  EXPECT_EQ(slurp(png).substr(1, 3), "PNG");
}

TEST(RolesCli, BadInputIsExitCodeTwoWithTheReason) {
  ScratchDir dir;
  std::ofstream(dir.file("scene.json")) << R"({"inputs": {"ct": "ct.nii.gz"}, "roles": {"source": "labels"}})";
  CliResult r = run_pneumo("roles " + dir.file("scene.json"));
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("inputs.labels"), std::string::npos) << r.err;
  // A PNG into a folder that does not exist is refused before any work.
  r = run_pneumo("roles " + dir.file("scene.json") + " --png " + dir.file("nowhere/x.png"));
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("nowhere"), std::string::npos) << r.err;
}
