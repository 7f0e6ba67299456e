// The deformation as a standard transform (warp/displacement_field.h): ITK applies pneumo's
// displacement_field.nii.gz (a vector image) and displacement_field_transform.h5 (a transform file)
// to the input CT with its own readers, DisplacementFieldTransform and linear resampler
// (tests/itk/apply_displacement_field.cpp), and must get pneumo's deformed CT from both.
// The case's voxel axes are permuted against the world (i superior, j right, k anterior), so the
// wall rises along k = world anterior, an axis whose sign LPS and RAS disagree on: a field in the
// wrong frame, or pushing instead of pulling, moves the wall the wrong way and fails. The CT is a
// linear ramp in every world direction (not piecewise constant), so any misplaced sample shows.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "cli_test_support.h"
#include "io/volume_io.h"
#include "io_test_support.h"
#include "tiny_case_support.h"

namespace pneumo {
namespace {

using namespace testing_support;

Geometry permuted_grid() {
  Geometry g = tiny_case_grid();
  g.direction << 0, 1, 0,   // j → +x (right)
                 0, 0, 1,   // k → +y (anterior)
                 1, 0, 0;   // i → +z (superior)
  return g;
}

/// The tiny case's labels on the permuted grid, and a CT that ramps with world position inside the
/// body (air stays −1000 HU, so the tissue/air edge is where the warp's samples differ most).
struct RampCase {
  Volume labels, ct;
};
RampCase ramp_case() {
  RampCase c{tiny_case_labels(), tiny_case_ct()};
  c.labels.geometry() = permuted_grid();
  c.ct.geometry() = permuted_grid();
  const Geometry& g = c.ct.geometry();
  for (int64_t k = 0; k < g.dims[2]; ++k)
    for (int64_t j = 0; j < g.dims[1]; ++j)
      for (int64_t i = 0; i < g.dims[0]; ++i) {
        const int64_t n = g.linear_index(i, j, k);
        if (c.labels.data<uint8_t>()[n] == kTinyAir) continue;
        const Vec3 x = g.to_world(Vec3(double(i), double(j), double(k)));
        c.ct.data<float>()[n] = float(2.0 * x[0] + 3.0 * x[1] - 1.5 * x[2]);
      }
  return c;
}

class DisplacementFieldOnGrid : public ::testing::TestWithParam<const char*> {};

// On the working grid (padded) and on the input's own (the box inside it, lo ≠ 0).
TEST_P(DisplacementFieldOnGrid, ItkAppliesItToTheCtAndGetsPneumosWarp) {
  ScratchDir d;
  nlohmann::json s = tiny_case_scene_json();
  s["output"] = {{"write_displacement_field", true}, {"write_slices", false}, {"grid", GetParam()}};
  // Padding makes the working grid larger than the input's on every side it grows: the input's
  // grid is then a box inside it whose first voxel is not the working grid's.
  s["roles"]["pad_anterior_mm"] = 10.0;
  s["roles"]["pad_lateral_mm"] = 10.0;
  const RampCase c = ramp_case();
  const std::string scene = write_tiny_case(d, s, c.ct, c.labels);
  ASSERT_EQ(run_pneumo("-q simulate " + scene + " --out " + d.file("out")).code, 0);
  const CliResult warp = run_pneumo("-q warp " + scene + " --out " + d.file("out"));
  ASSERT_EQ(warp.code, 0) << warp.err;
  const Volume by_pneumo = read_volume(d.file("out/deformed_ct.nii.gz"));
  const Volume labels = read_volume(d.file("out/deformed_labels.nii.gz"));
  ASSERT_EQ(by_pneumo.type(), VoxelType::Float32);
  const nlohmann::json metrics = nlohmann::json::parse(slurp(d.file("out/metrics.json")));
  ASSERT_EQ(int64_t(metrics["cavity_specks_filled"]["voxels"]), 0) << "a filled speck has no source to compare";

  // The field moved something: the original CT on the same grid differs from the warped one.
  const int64_t n = by_pneumo.voxel_count();
  int64_t moved = 0;
  for (int64_t v = 0; v < n; ++v) {
    const Geometry& g = by_pneumo.geometry();
    const int64_t i = v % g.dims[0], j = (v / g.dims[0]) % g.dims[1], k = v / (g.dims[0] * g.dims[1]);
    const Vec3 in_ct = c.ct.geometry().to_index(g.to_world(Vec3(double(i), double(j), double(k))));
    const Index3 q{std::llround(in_ct[0]), std::llround(in_ct[1]), std::llround(in_ct[2])};
    bool inside = true;
    for (int a = 0; a < 3; ++a) inside = inside && q[a] >= 0 && q[a] < c.ct.geometry().dims[a];
    const double before = inside ? c.ct.value(q[0], q[1], q[2]) : -1000.0;
    if (std::abs(before - by_pneumo.data<float>()[v]) > 5.0) ++moved;
  }
  EXPECT_GT(moved, 50) << "the warp moved almost nothing: the comparison would prove little";

  // The vector image, read by ITK as an image, and the transform file, read by its TransformFileReader.
  for (const char* field : {"displacement_field.nii.gz", "displacement_field_transform.h5"}) {
    SCOPED_TRACE(field);
    const CliResult itk = run_shell(std::string(PNEUMO_ITK_APPLY_FIELD) + " " + d.file("ct.nii.gz") + " " +
                                    d.file(std::string("out/") + field) + " " + d.file("itk.nii.gz"));
    ASSERT_EQ(itk.code, 0) << itk.err;
    const Volume by_itk = read_volume(d.file("itk.nii.gz"));
    ASSERT_TRUE(by_itk.geometry().same_grid(by_pneumo.geometry(), 1e-3)) << "ITK resampled onto another grid";
    ASSERT_EQ(by_itk.type(), VoxelType::Float32);
    // Both sample the same CT at the same points by the same trilinear rule; they differ by the
    // float32 rounding of u (≤ 2^-24 |u| plus the warp's float samples of the index, < 2^-9 voxel),
    // times the steepest slope, 1000 HU over one 5 mm voxel at the tissue/air edge: 0.5 HU bounds it.
    double worst = 0.0;
    int64_t compared = 0;
    for (int64_t v = 0; v < n; ++v) {
      if (labels.value(v) == 250) continue;   // the cavity: new gas, no source (u = 0 there)
      worst = std::max(worst, std::abs(double(by_itk.data<float>()[v]) - double(by_pneumo.data<float>()[v])));
      ++compared;
    }
    EXPECT_GT(compared, n / 2);
    EXPECT_LT(worst, 0.5) << "ITK's resampling through pneumo's field differs from pneumo's warp by " << worst
                          << " HU";
    std::printf("%s: ITK's resampling is within %.3g HU of pneumo's warp over %lld voxels\n", field, worst,
                static_cast<long long>(compared));
  }
}
INSTANTIATE_TEST_SUITE_P(DisplacementField, DisplacementFieldOnGrid, ::testing::Values("working", "input"));

TEST(DisplacementField, NibabelReadsAVectorImageInMillimetres) {
  ScratchDir d;
  nlohmann::json s = tiny_case_scene_json();
  s["output"] = {{"write_displacement_field", true}, {"write_slices", false}};
  const std::string scene = write_tiny_case(d, s);
  ASSERT_EQ(run_pneumo("-q run " + scene + " --out " + d.file("out")).code, 0);
  const std::string py =
      "import nibabel, numpy, sys\n"
      "f = nibabel.load(sys.argv[1]); h = f.header\n"
      "u = numpy.asarray(f.dataobj)\n"
      "print(list(u.shape), int(h['intent_code']), h['intent_name'].tobytes().rstrip(b'\\0').decode(),\n"
      "      h.get_xyzt_units()[0], str(u.dtype), float(numpy.abs(u).max()), bool(numpy.isfinite(u).all()))\n";
  write_bytes(d.file("read.py"), py);
  const CliResult r = run_shell(std::string(PNEUMO_VTK_PYTHON) + " " + d.file("read.py") + " " +
                                d.file("out/displacement_field.nii.gz"));
  ASSERT_EQ(r.code, 0) << r.err;
  const Volume ct = read_volume(d.file("out/deformed_ct.nii.gz"));
  const Index3 g = ct.geometry().dims;
  char want[160];
  std::snprintf(want, sizeof want, "[%lld, %lld, %lld, 1, 3] 1007 LPS mm pullback mm float32", (long long)g[0],
                (long long)g[1], (long long)g[2]);
  EXPECT_EQ(r.out.rfind(want, 0), 0u) << r.out;
  EXPECT_NE(r.out.find("True"), std::string::npos) << "a non-finite displacement: " << r.out;
  const nlohmann::json metrics = nlohmann::json::parse(slurp(d.file("out/metrics.json")));
  // The largest displacement is about the wall's largest (the field holds pull-backs of the same motion).
  const double largest = std::stod(r.out.substr(r.out.find("float32") + 8));
  EXPECT_GT(largest, 0.5 * double(metrics["max_wall_displacement_mm"]));
  EXPECT_LT(largest, 1.5 * double(metrics["max_wall_displacement_mm"]) + 5.0);
}

TEST(DisplacementField, NotWrittenUnlessAsked) {
  ScratchDir d;
  const std::string scene = write_tiny_case(d);
  ASSERT_EQ(run_pneumo("-q run " + scene + " --out " + d.file("out")).code, 0);
  EXPECT_TRUE(std::filesystem::exists(d.file("out/deformed_ct.nii.gz")));
  EXPECT_FALSE(std::filesystem::exists(d.file("out/displacement_field.nii.gz")));
  EXPECT_FALSE(std::filesystem::exists(d.file("out/displacement_field_transform.h5")));
}

}  // namespace
}  // namespace pneumo
