// `pneumo convert` writes nothing over an existing file unless told to (--force), and that holds for
// every file a conversion writes: a .mhd header's data file (.raw) beside it too, which was
// overwritten without --force while only the header's name was checked.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "cli_test_support.h"
#include "io/volume_io.h"
#include "tiny_case_support.h"

namespace pneumo {
namespace {

using namespace testing_support;

TEST(Convert, AnMhdsDataFileIsOverwrittenOnlyWithForce) {
  ScratchDir d;
  write_volume(tiny_case_ct(), d.file("ct.nii.gz"));
  write_bytes(d.file("out.raw"), "someone else's data");
  CliResult r = run_pneumo("-q convert " + d.file("ct.nii.gz") + " " + d.file("out.mhd"));
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find(d.file("out.raw") + ": already exists (the data file " + d.file("out.mhd") +
                       " names); use --force to overwrite"),
            std::string::npos)
      << r.err;
  EXPECT_EQ(read_bytes(d.file("out.raw")), "someone else's data");
  EXPECT_FALSE(std::filesystem::exists(d.file("out.mhd"))) << "nothing written";

  r = run_pneumo("-q convert --force " + d.file("ct.nii.gz") + " " + d.file("out.mhd"));
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(read_volume(d.file("out.mhd")).same_voxels(tiny_case_ct()));
  // The single-file formats write only what they are named: an unrelated .raw beside them stays.
  write_bytes(d.file("ct2.raw"), "kept");
  EXPECT_EQ(run_pneumo("-q convert " + d.file("ct.nii.gz") + " " + d.file("ct2.mha")).code, 0);
  EXPECT_EQ(read_bytes(d.file("ct2.raw")), "kept");
}

TEST(Convert, TheFilesAConversionWritesAreNamedByTheFormat) {
  EXPECT_EQ(files_written_by("a/ct.mhd"), (std::vector<std::string>{"a/ct.mhd", "a/ct.raw"}));
  EXPECT_EQ(files_written_by("a/ct.mhd", WriteOptions{true}), (std::vector<std::string>{"a/ct.mhd", "a/ct.zraw"}));
  for (const char* single : {"ct.mha", "ct.nii", "ct.nii.gz", "ct.nrrd"})
    EXPECT_EQ(files_written_by(single), std::vector<std::string>{single});
}

}  // namespace
}  // namespace pneumo
