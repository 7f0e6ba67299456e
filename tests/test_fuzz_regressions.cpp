// Inputs the fuzzers (tests/fuzz, scripts/fuzz.sh) found mishandled, each kept as a test once fixed.
// Compared for each: what the user sees from `pneumo info FILE`: exit code 2 and exactly one line on
// stderr naming the file and the problem (nothing printed by a library behind pneumo's back).
#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>

#include "cli_test_support.h"
#include "io/volume_io.h"

namespace pneumo {
namespace {

using namespace testing_support;

int lines(const std::string& s) { return int(std::count(s.begin(), s.end(), '\n')); }

/// A valid 3×2×2 int16 .nii with one int16 of its header replaced.
std::string nifti_with_header_short(const ScratchDir& d, std::size_t offset, int16_t value) {
  Geometry g;
  g.dims = {3, 2, 2};
  Volume v(g, VoxelType::Int16);
  const std::string path = d.file("x.nii");
  write_volume(v, path);
  std::string bytes = read_bytes(path);
  std::memcpy(&bytes[offset], &value, sizeof value);
  write_bytes(path, bytes);
  return path;
}

TEST(FuzzRegressions, NiftiZeroOrNegativeDimIsOneLine) {
  // fuzz_nifti: a header with dim[i] ≤ 0 made niftilib print "** ERROR: nifti_convert_n1hdr2nim: bad
  // dim[i]" on stderr before pneumo's own message: two lines for one problem. dim[] starts at byte 40 of
  // nifti_1_header (dim[0] at 40, dim[1] at 42, ...).
  for (const int16_t bad : {int16_t(0), int16_t(-3)})
    for (const std::size_t axis : {1u, 2u, 3u}) {
      SCOPED_TRACE("dim[" + std::to_string(axis) + "] = " + std::to_string(bad));
      ScratchDir d;
      const std::string path = nifti_with_header_short(d, 40 + 2 * axis, bad);
      const CliResult r = run_pneumo("info " + path);
      EXPECT_EQ(r.code, 2) << r.err;
      EXPECT_EQ(lines(r.err), 1) << r.err;
      EXPECT_NE(r.err.find(path + ": dimension " + std::to_string(axis - 1) + " is " + std::to_string(bad)),
                std::string::npos)
          << r.err;
    }
}

}  // namespace
}  // namespace pneumo
