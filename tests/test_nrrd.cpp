// NRRD in and out (io/nrrd_io.h): pneumo's NRRD round-trips every voxel type and an oblique frame
// bit for bit; ITK (through which 3D Slicer reads and writes NRRD) reads pneumo's files at the same
// world points and pneumo reads ITK's; what is not one placed volume is refused saying why.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <type_traits>

#include "cli_test_support.h"
#include "io/volume_io.h"
#include "io_test_support.h"
#include "tiny_case_support.h"

namespace pneumo {
namespace {

using namespace testing_support;

const std::string kRealCt = std::string(PNEUMO_SOURCE_DIR) + "/data/totalseg-example-ct/example_ct.nii.gz";

/// The tiny case's grid turned 30° about the body axis and flipped along k, with a ramp of whole HU.
Volume oblique_ramp(VoxelType type) {
  Geometry g = tiny_case_grid();
  const double c = std::cos(M_PI / 6.0), s = std::sin(M_PI / 6.0);
  g.direction << c, -s, 0,
                 s, c, 0,
                 0, 0, -1;
  g.origin_mm = Vec3(-12.5, 40.25, 101.0);
  Volume v(g, type);
  for (int64_t n = 0; n < g.voxel_count(); ++n) {
    const double x = double(n % 97);   // within every type's range
    dispatch_voxel_type(type, v.raw(), [&](auto* p) { p[n] = static_cast<std::remove_pointer_t<decltype(p)>>(x); });
  }
  return v;
}

TEST(Nrrd, EveryVoxelTypeRoundTripsBitForBitInAnObliqueFrame) {
  ScratchDir d;
  for (const VoxelType t : {VoxelType::Int8, VoxelType::UInt8, VoxelType::Int16, VoxelType::UInt16, VoxelType::Int32,
                            VoxelType::UInt32, VoxelType::Float32, VoxelType::Float64}) {
    SCOPED_TRACE(voxel_type_name(t));
    const Volume v = oblique_ramp(t);
    write_volume(v, d.file("v.nrrd"));
    const Volume back = read_volume(d.file("v.nrrd"));
    EXPECT_TRUE(back.same_voxels(v));
    EXPECT_TRUE(back.geometry().same_grid(v.geometry(), 1e-9));
  }
}

/// Every voxel of `a` and `b` equal, on the same grid (`tol_mm`).
void expect_same_volume(const Volume& a, const Volume& b, double tol_mm) {
  ASSERT_TRUE(a.geometry().same_grid(b.geometry(), tol_mm));
  int64_t differ = 0;
  for (int64_t n = 0; n < a.voxel_count(); ++n) differ += a.value(n) != b.value(n);
  EXPECT_EQ(differ, 0) << "voxels that differ";
}

TEST(Nrrd, ItkReadsPneumosNrrdAndPneumoReadsItks) {
  ScratchDir d;
  write_volume(oblique_ramp(VoxelType::Int16), d.file("oblique.nii.gz"));
  for (const std::string& source : {kRealCt, d.file("oblique.nii.gz")}) {
    SCOPED_TRACE(source);
    const Volume original = read_volume(source);
    // pneumo writes NRRD, ITK reads it and writes NIfTI, pneumo reads that.
    ASSERT_EQ(run_pneumo("-q convert " + source + " " + d.file("by_pneumo.nrrd") + " --force").code, 0);
    CliResult r = run_shell(std::string(PNEUMO_ITK_CONVERT) + " " + d.file("by_pneumo.nrrd") + " " +
                            d.file("through_itk.nii.gz"));
    ASSERT_EQ(r.code, 0) << r.err;
    expect_same_volume(read_volume(d.file("through_itk.nii.gz")), original, 1e-4);
    // ITK writes NRRD (gzip), as Slicer saves a volume, and pneumo reads it.
    r = run_shell(std::string(PNEUMO_ITK_CONVERT) + " " + source + " " + d.file("by_itk.nrrd"));
    ASSERT_EQ(r.code, 0) << r.err;
    expect_same_volume(read_volume(d.file("by_itk.nrrd")), original, 1e-4);
  }
}

TEST(Nrrd, ADetachedHeaderReadsItsDataFile) {
  ScratchDir d;
  const Volume v = oblique_ramp(VoxelType::Int16);
  std::string raw(static_cast<const char*>(v.raw()), v.byte_count());
  write_bytes(d.file("v.raw"), raw);
  write_bytes(d.file("v.nhdr"),
              "NRRD0004\ntype: short\ndimension: 3\nspace: right-anterior-superior\nsizes: 16 16 10\n"
              "space directions: (4.330127018922194,2.5,0) (-2.5,4.330127018922194,0) (0,0,-5)\n"
              "kinds: domain domain domain\nendian: little\nencoding: raw\nspace origin: (-12.5,40.25,101)\n"
              "data file: v.raw\n");
  expect_same_volume(read_volume(d.file("v.nhdr")), v, 1e-9);
}

TEST(Nrrd, WhatIsNotOnePlacedVolumeIsRefusedSayingWhy) {
  ScratchDir d;
  const std::string data(2 * 2 * 2 * 2, '\0');
  const struct {
    const char* name;
    std::string header;
    const char* says;
  } cases[] = {
      {"no_space.nrrd", "NRRD0004\ntype: short\ndimension: 3\nsizes: 2 2 2\nspacings: 1 1 1\nendian: little\nencoding: raw\n\n",
       "has no \"space\""},
      {"no_origin.nrrd",
       "NRRD0004\ntype: short\ndimension: 3\nspace: left-posterior-superior\nsizes: 2 2 2\n"
       "space directions: (1,0,0) (0,1,0) (0,0,1)\nendian: little\nencoding: raw\n\n",
       "no \"space origin\""},
      {"four_d.nrrd",
       "NRRD0004\ntype: short\ndimension: 4\nspace: left-posterior-superior\nsizes: 1 2 2 2\n"
       "space directions: none (1,0,0) (0,1,0) (0,0,1)\nspace origin: (0,0,0)\nendian: little\nencoding: raw\n\n",
       "4 dimensions"},
      {"not_patient.nrrd",
       "NRRD0004\ntype: short\ndimension: 3\nspace: 3D-right-handed\nsizes: 2 2 2\n"
       "space directions: (1,0,0) (0,1,0) (0,0,1)\nspace origin: (0,0,0)\nendian: little\nencoding: raw\n\n",
       "not patient-oriented"},
      {"truncated.nrrd",
       "NRRD0004\ntype: short\ndimension: 3\nspace: left-posterior-superior\nsizes: 2 2 9\n"
       "space directions: (1,0,0) (0,1,0) (0,0,1)\nspace origin: (0,0,0)\nendian: little\nencoding: raw\n\n",
       "truncated"},
      {"absurd.nrrd",
       "NRRD0004\ntype: short\ndimension: 3\nspace: left-posterior-superior\nsizes: 1048576 1048576 1048576\n"
       "space directions: (1,0,0) (0,1,0) (0,0,1)\nspace origin: (0,0,0)\nendian: little\nencoding: raw\n\n",
       "absurd"},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.name);
    write_bytes(d.file(c.name), c.header + data);
    const CliResult r = run_pneumo(std::string("info ") + d.file(c.name));
    EXPECT_EQ(r.code, 2) << r.err;
    EXPECT_NE(r.err.find(c.says), std::string::npos) << r.err;
    EXPECT_NE(r.err.find(d.file(c.name)), std::string::npos) << "names the file: " << r.err;
  }
}

TEST(Nrrd, ConvertRefusesToOverwriteAndADetachedName) {
  ScratchDir d;
  write_volume(tiny_case_ct(), d.file("ct.nii.gz"));
  ASSERT_EQ(run_pneumo("-q convert " + d.file("ct.nii.gz") + " " + d.file("ct.nrrd")).code, 0);
  CliResult r = run_pneumo("-q convert " + d.file("ct.nii.gz") + " " + d.file("ct.nrrd"));
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("--force"), std::string::npos) << r.err;
  r = run_pneumo("-q convert " + d.file("ct.nii.gz") + " " + d.file("ct.nhdr"));
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find(".nrrd"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace pneumo
