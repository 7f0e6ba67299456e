// DICOM CT series in (io/dicom_io.h): series written by another library (pydicom,
// tests/dicom/write_ct_series.py) from a NIfTI must read as that NIfTI, voxel for voxel and at the
// same world points; what is not one CT volume is refused with a message that says what is wrong.
#include <gtest/gtest.h>

#include <sys/stat.h>

#include <cmath>
#include <filesystem>
#include <string>

#include <nlohmann/json.hpp>

#include "cli_test_support.h"
#include "io/volume_io.h"
#include "io_test_support.h"
#include "tiny_case_support.h"

namespace pneumo {
namespace {

using namespace testing_support;

const std::string kRealCt = std::string(PNEUMO_SOURCE_DIR) + "/data/totalseg-example-ct/example_ct.nii.gz";

/// Writes the series of `nifti` into `dir` with the generator's options ("key=value ...").
void write_series(const std::string& nifti, const std::string& dir, const std::string& options = "") {
  const CliResult r = run_shell(std::string(PNEUMO_VTK_PYTHON) + " " + PNEUMO_SOURCE_DIR +
                                "/tests/dicom/write_ct_series.py " + nifti + " " + dir + " " + options);
  ASSERT_EQ(r.code, 0) << r.err;
}

TEST(DicomSeries, TheRealCtAsASeriesIsTheNiftiVoxelForVoxel) {
  ScratchDir d;
  write_series(kRealCt, d.file("series"));   // shuffled file names, HU = stored − 2048
  const Volume nifti = read_volume(kRealCt);
  const Volume dicom = read_volume(d.file("series"));
  ASSERT_EQ(dicom.type(), VoxelType::Float32);
  // Positions travel as ten-digit decimal strings: 1e-7 mm; 1e-4 mm is far below any voxel.
  ASSERT_TRUE(dicom.geometry().same_grid(nifti.geometry(), 1e-4));
  int64_t differ = 0;
  for (int64_t n = 0; n < nifti.voxel_count(); ++n) differ += dicom.value(n) != nifti.value(n);
  EXPECT_EQ(differ, 0) << "voxels whose HU differ";
}

TEST(DicomSeries, AnObliqueSeriesInReverseSliceOrderLandsOnTheSameWorldPoints) {
  // Rotated 30° about the body axis and with k towards the feet: DICOM's slice normal (row × column)
  // then points against k, so the reader's slices run the other way and its grid is not the
  // NIfTI's; every voxel must still sit on a NIfTI voxel centre and hold its HU.
  ScratchDir d;
  Geometry g = tiny_case_grid();
  const double c = std::cos(M_PI / 6.0), s = std::sin(M_PI / 6.0);
  g.direction << c, -s, 0,
                 s, c, 0,
                 0, 0, -1;
  Volume ct(g, VoxelType::Float32);
  for (int64_t k = 0; k < g.dims[2]; ++k)
    for (int64_t j = 0; j < g.dims[1]; ++j)
      for (int64_t i = 0; i < g.dims[0]; ++i) {
        const Vec3 x = g.to_world(Vec3(double(i), double(j), double(k)));
        ct.data<float>()[g.linear_index(i, j, k)] = float(std::round(2.0 * x[0] + 3.0 * x[1] - 1.5 * x[2]));
      }
  write_volume(ct, d.file("oblique.nii.gz"));
  write_series(d.file("oblique.nii.gz"), d.file("series"), "slope=0.5 intercept=-1500");
  const Volume dicom = read_volume(d.file("series"));
  const Geometry& h = dicom.geometry();
  ASSERT_EQ(h.voxel_count(), g.voxel_count());
  EXPECT_LT(h.direction.col(2).dot(g.direction.col(2)), -0.999) << "the slices should run against k";
  double worst_offset = 0.0;
  int64_t differ = 0;
  for (int64_t k = 0; k < h.dims[2]; ++k)
    for (int64_t j = 0; j < h.dims[1]; ++j)
      for (int64_t i = 0; i < h.dims[0]; ++i) {
        const Vec3 q = g.to_index(h.to_world(Vec3(double(i), double(j), double(k))));
        const Vec3 r(std::round(q[0]), std::round(q[1]), std::round(q[2]));
        worst_offset = std::max(worst_offset, (q - r).cwiseAbs().maxCoeff());
        ASSERT_TRUE(r.minCoeff() >= 0 && r[0] < g.dims[0] && r[1] < g.dims[1] && r[2] < g.dims[2]);
        differ += dicom.value(i, j, k) != ct.value(int64_t(r[0]), int64_t(r[1]), int64_t(r[2]));
      }
  EXPECT_LT(worst_offset, 1e-4) << "voxel index units";
  EXPECT_EQ(differ, 0);
}

TEST(DicomSeries, WhatIsNotOneCtVolumeIsRefusedSayingWhy) {
  ScratchDir d;
  write_volume(tiny_case_ct(), d.file("ct.nii.gz"));
  const struct {
    const char* options;
    const char* says;
  } cases[] = {
      {"split=1", "2 series"},
      {"modality=MR", "modality \"MR\""},
      {"drop=4", "not evenly spaced"},
      {"tilt_mm=1", "tilted gantry"},
      {"short_pixels=1", "bytes where Rows × Columns need"},
      // GDCM reads a slope of 0 as 1; 1e300 made infinite voxels: the tags are refused, naming them.
      {"tag_slope=0", ".dcm: Rescale Slope (0028,1053) is 0"},
      {"tag_slope=1e300", ".dcm: Rescale Slope (0028,1053) 1e+300 and Intercept (0028,1052) -2048 map its stored"},
  };
  int index = 0;
  for (const auto& c : cases) {
    SCOPED_TRACE(c.options);
    const std::string dir = d.file("series" + std::to_string(index++));
    write_series(d.file("ct.nii.gz"), dir, c.options);
    const CliResult r = run_pneumo("info " + dir);
    EXPECT_EQ(r.code, 2) << r.err;
    EXPECT_NE(r.err.find(c.says), std::string::npos) << r.err;
    EXPECT_NE(r.err.find(dir), std::string::npos) << "the message names the folder: " << r.err;
  }
  // A folder without DICOM in it.
  std::filesystem::create_directories(d.file("notes"));
  write_bytes(d.file("notes/readme.txt"), "not an image\n");
  const CliResult r = run_pneumo("info " + d.file("notes"));
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("holds no DICOM file"), std::string::npos) << r.err;
}

TEST(DicomSeries, AFifoOrADanglingLinkAmongTheSlicesIsRefusedNamingIt) {
  // GDCM's own listing stopped at the first entry it could not stat (a dangling link: the slices
  // listed before it were read as the CT, exit 0) and its scan opened a FIFO (waiting for ever).
  // The names sort among the slices' (hexadecimal names), so neither is first or last.
  ScratchDir d;
  write_volume(tiny_case_ct(), d.file("ct.nii.gz"));
  const struct {
    const char* entry;
    const char* says;
  } cases[] = {{"8fifo.dcm", "8fifo.dcm is a FIFO (named pipe), not a regular file: move it out of the folder"},
               {"8dangling.dcm", "8dangling.dcm is a symbolic link to"}};
  for (const auto& c : cases) {
    SCOPED_TRACE(c.entry);
    const std::string dir = d.file(std::string("series_") + c.entry);
    write_series(d.file("ct.nii.gz"), dir);
    const std::string entry = dir + "/" + c.entry;
    if (std::string(c.entry) == "8fifo.dcm") ASSERT_EQ(::mkfifo(entry.c_str(), 0600), 0);
    else std::filesystem::create_symlink(dir + "/gone.dcm", entry);
    const CliResult r = run_pneumo_within(60, "info " + dir);
    EXPECT_EQ(r.code, 2) << "124 or 137: it waited on the FIFO; " << r.err;
    EXPECT_EQ(count_occurrences(r.err, "\n"), 1) << "one line: " << r.err;
    EXPECT_NE(r.err.find(dir + ": " + c.says), std::string::npos) << r.err;
  }
}

TEST(DicomSeries, SubFoldersAreSkippedAndOtherFilesAreNoSlices) {
  // A sub-folder (or a link to one) is another series or an export's extras: skipped, and said so;
  // a dot file (.DS_Store), a note or a short file of other bytes is a regular file that is not DICOM.
  ScratchDir d;
  write_volume(tiny_case_ct(), d.file("ct.nii.gz"));
  write_series(d.file("ct.nii.gz"), d.file("series"));
  const Volume clean = read_volume(d.file("series"));
  std::filesystem::create_directories(d.file("series/extras"));
  std::filesystem::create_directory_symlink(d.file("series/extras"), d.file("series/link_to_extras"));
  write_bytes(d.file("series/.DS_Store"), std::string("\0\0\0\1Bud1", 8));
  write_bytes(d.file("series/notes.txt"), "the scanner's notes\n");
  // Nine bytes that stop Debian's GDCM 3.0 on an assert() when it scans them (found by fuzzing):
  // passed over before GDCM sees them, as every file that does not start as a DICOM file does.
  write_bytes(d.file("series/xb"), std::string("\x02\x00\x2b\x28\x02\x00\x2b\x01\x02", 9));
  const Volume v = read_volume(d.file("series"));
  EXPECT_TRUE(v.same_voxels(clean));
  EXPECT_TRUE(v.geometry().same_grid(clean.geometry(), 0.0));
  const CliResult r = run_pneumo_within(60, "info " + d.file("series"));
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("skipped the sub-folder extras"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("skipped the sub-folder link_to_extras"), std::string::npos) << r.err;
}

TEST(DicomSeries, ASceneTakesTheSeriesFolderAsItsCtAndSolvesTheSameCase) {
  ScratchDir d;
  write_tiny_case(d);
  write_series(d.file("ct.nii.gz"), d.file("ct_dicom"));
  nlohmann::json scene = tiny_case_scene_json();
  scene["inputs"]["ct"] = "ct_dicom";
  write_bytes(d.file("scene_dicom.json"), scene.dump(2) + "\n");
  ASSERT_EQ(run_pneumo("-q simulate " + d.file("scene.json") + " --out " + d.file("nifti")).code, 0);
  const CliResult r = run_pneumo("-q simulate " + d.file("scene_dicom.json") + " --out " + d.file("dicom"));
  ASSERT_EQ(r.code, 0) << r.err;
  const auto metrics = [&](const char* run) {
    return nlohmann::json::parse(slurp(d.file(std::string(run) + "/metrics.json")));
  };
  EXPECT_EQ(double(metrics("dicom")["max_wall_displacement_mm"]), double(metrics("nifti")["max_wall_displacement_mm"]));
}

}  // namespace
}  // namespace pneumo
