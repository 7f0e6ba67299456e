// A disk that fills during `pneumo warp`: niftilib
// writes through gzwrite without checking it, and once left a truncated deformed_ct.nii.gz under its
// final name, with two of its own error lines naming a temporary file. The disk is filled here by
// a file-size limit on the process (RLIMIT_FSIZE, SIGXFSZ ignored, so writes past it fail with
// EFBIG as on a full disk), which needs no mount and cannot touch anything else.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <random>
#include <set>
#include <string>

#include "cli_test_support.h"
#include "io_test_support.h"
#include "tiny_case_support.h"

namespace pneumo {
namespace {

using namespace testing_support;
namespace fs = std::filesystem;

/// `pneumo ARGS` with writes limited to `kib` KiB per file.
CliResult run_pneumo_with_file_limit(int kib, const std::string& args) {
  return run_shell("bash -c \"trap '' XFSZ; ulimit -f " + std::to_string(kib) + "; exec " + PNEUMO_CLI_PATH + " " + args +
                   "\"");
}

TEST(FullDisk, AWarpThatCannotWriteItsCtLeavesNoFileUnderItsNameAndSaysWhich) {
  ScratchDir d;
  // Tissue with texture (±100 HU), as a CT has: its deformed CT does not compress below the limit.
  Volume ct = tiny_case_ct();
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> noise(-100.0f, 100.0f);
  for (int64_t n = 0; n < ct.voxel_count(); ++n)
    if (ct.data<float>()[n] > -1000.0f) ct.data<float>()[n] += noise(rng);
  const std::string scene = write_tiny_case(d, tiny_case_scene_json(), ct);
  ASSERT_EQ(run_pneumo("-q simulate " + scene + " --out " + d.file("out")).code, 0);
  const std::string metrics_before = slurp(d.file("out/metrics.json"));
  const auto before = tree(d.path() / "out");
  // 1 KiB a file: the simulation's files are already there; the deformed CT (a few KiB) is written first.
  const CliResult r = run_pneumo_with_file_limit(1, "-q warp " + scene + " --out " + d.file("out"));
  EXPECT_EQ(r.code, 1) << r.err;
  EXPECT_NE(r.err.find("deformed_ct.nii.gz: writing failed"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("** ERROR"), std::string::npos) << "niftilib's own lines reached the user: " << r.err;
  EXPECT_EQ(r.err.find(".tmp"), std::string::npos) << "a temporary name reached the user: " << r.err;
  EXPECT_EQ(tree(d.path() / "out"), before) << "a file appeared, complete-looking or temporary";
  EXPECT_EQ(slurp(d.file("out/metrics.json")), metrics_before);
  // Without the limit the same warp writes it whole (the control: the case itself is fine).
  const CliResult ok = run_pneumo("-q warp " + scene + " --out " + d.file("out"));
  ASSERT_EQ(ok.code, 0) << ok.err;
  EXPECT_TRUE(fs::exists(d.file("out/deformed_ct.nii.gz")));
}

/// Bytes of `dir/name`.
uint64_t file_bytes(const ScratchDir& d, const std::string& name) { return fs::file_size(d.file(name)); }

// A warp writes three images, then metrics.json. When the last image fails, the first two
// (written whole) are removed too: they would otherwise look like a finished warp's, and the next
// `pneumo warp` refused them as "already holds a warp".
TEST(FullDisk, AWarpThatFailsAfterItsFirstImagesRemovesThemAndCanBeRunAgain) {
  ScratchDir d;
  const std::string scene = write_tiny_case(d, tiny_case_scene_json(), tiny_case_ct());
  ASSERT_EQ(run_pneumo("-q simulate " + scene + " --out " + d.file("out")).code, 0);
  ASSERT_EQ(run_pneumo("-q simulate " + scene + " --out " + d.file("probe")).code, 0);
  ASSERT_EQ(run_pneumo("-q warp " + scene + " --out " + d.file("probe")).code, 0);
  // A per-file limit that the two NIfTIs and metrics.json fit under and the slices PNG does not.
  const uint64_t largest = std::max({file_bytes(d, "probe/deformed_ct.nii.gz"), file_bytes(d, "probe/deformed_labels.nii.gz"),
                                     file_bytes(d, "probe/metrics.json")});
  const int kib = int(largest / 1024 + 2);
  ASSERT_GT(file_bytes(d, "probe/slices_before_after.png"), uint64_t(kib) * 1024) << "the case no longer separates them";
  const std::string metrics_before = slurp(d.file("out/metrics.json"));
  const auto before = tree(d.path() / "out");
  const CliResult r = run_pneumo_with_file_limit(kib, "-q warp " + scene + " --out " + d.file("out"));
  EXPECT_EQ(r.code, 1) << r.err;
  EXPECT_NE(r.err.find("slices_before_after.png"), std::string::npos) << r.err;
  EXPECT_EQ(tree(d.path() / "out"), before) << "the images written before the failure stayed";
  EXPECT_EQ(slurp(d.file("out/metrics.json")), metrics_before);
  const CliResult again = run_pneumo("-q warp " + scene + " --out " + d.file("out"));
  ASSERT_EQ(again.code, 0) << "a failed warp blocked the next one: " << again.err;

  // Replacing a finished warp (--force) that fails leaves no warp, not the old metrics over new images.
  const CliResult forced = run_pneumo_with_file_limit(kib, "-q warp " + scene + " --out " + d.file("out") + " --force");
  EXPECT_EQ(forced.code, 1) << forced.err;
  EXPECT_FALSE(fs::exists(d.file("out/deformed_ct.nii.gz"))) << forced.err;
  EXPECT_FALSE(nlohmann::json::parse(slurp(d.file("out/metrics.json"))).contains("warp")) << "still marked as warped";
  EXPECT_EQ(run_pneumo("-q warp " + scene + " --out " + d.file("out")).code, 0);
}


// Whichever file a full disk stops, the run failed on valid input: exit 1 and one line naming the
// file, never exit 2 (bad input), whose advice would send the user to the wrong place. Swept over
// per-file limits just below each file `simulate` writes, so that each size class fails in turn
// (the meshes, the deformation, the plots and the JSON files).
TEST(FullDisk, EveryFileSimulateCannotWriteExitsOneNamingIt) {
  ScratchDir d;
  const std::string scene = write_tiny_case(d, tiny_case_scene_json(), tiny_case_ct());
  ASSERT_EQ(run_pneumo("-q simulate " + scene + " --out " + d.file("probe")).code, 0);
  std::set<int> limits_kib;
  for (const auto& e : fs::directory_iterator(d.file("probe")))
    if (e.is_regular_file() && e.file_size() > 1024) limits_kib.insert(int((e.file_size() - 1) / 1024));
  ASSERT_GE(limits_kib.size(), 2u);
  for (const int kib : limits_kib) {
    SCOPED_TRACE(std::to_string(kib) + " KiB");
    const std::string out = d.file("out_" + std::to_string(kib));
    const CliResult r = run_pneumo_with_file_limit(kib, "-q simulate " + scene + " --out " + out);
    EXPECT_EQ(r.code, 1) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_NE(r.err.find(out), std::string::npos) << "the file is not named: " << r.err;
    EXPECT_EQ(r.err.find(".tmp"), std::string::npos) << "a temporary name reached the user: " << r.err;
  }
}

}  // namespace
}  // namespace pneumo
