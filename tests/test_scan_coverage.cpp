// What a scan covers, in words (roles/scan_coverage.h), on the example CT and on it cropped as
// clinical scans are: above the pelvis (at L3) and through the liver's middle.
#include <gtest/gtest.h>

#include <algorithm>

#include "core/progress.h"
#include "crop_test_support.h"
#include "example_roles_support.h"
#include "io/volume_io.h"
#include "pipeline/scene_stages.h"
#include "roles/scan_coverage.h"
#include "scene/scene.h"

using namespace pneumo;
using namespace pneumo::testing_support;

namespace {

struct Case {
  Volume ct, labels;
};

ScanCoverage coverage_of(const Case& c) {
  const Scene s = load_scene(std::string(PNEUMO_SOURCE_DIR) + "/scenes/totalseg_example.json");
  const RoleVolume rv = assign_roles(s, c.ct, &c.labels);
  return scan_coverage(rv, s.roles.label_names);
}

bool has(const std::vector<std::string>& v, const std::string& s) { return std::find(v.begin(), v.end(), s) != v.end(); }

bool warns_of(const ScanCoverage& c, const std::string& word) {
  for (const std::string& w : c.warnings)
    if (w.find(word) != std::string::npos) return true;
  return false;
}

}  // namespace

TEST(ScanCoverage, TheExampleRunsFromTheLungBasesToThePelvisCutThroughTheLiver) {
  PNEUMO_REQUIRE_REAL_CT();
  Progress::set_enabled(false);
  const Case full{read_volume(example_ct_path()), read_volume(example_labels_path())};
  const ScanCoverage c = coverage_of(full);
  EXPECT_TRUE(c.lungs_in_view);
  EXPECT_TRUE(c.pelvis_in_view);
  EXPECT_TRUE(c.top.cuts_body);
  EXPECT_TRUE(c.bottom.cuts_body);
  EXPECT_TRUE(has(c.top.structures, "liver")) << c.summary;   // the example's top slice is through the liver
  EXPECT_TRUE(warns_of(c, "cuts the liver")) << c.summary;
  EXPECT_FALSE(warns_of(c, "no pelvis"));
  EXPECT_FALSE(c.wall_cut_anteriorly);   // 12 mm of air in front of the skin
  EXPECT_NE(c.summary.find("lung bases"), std::string::npos) << c.summary;
}

TEST(ScanCoverage, CroppedAtL3TheScanSaysThePelvisIsMissing) {
  PNEUMO_REQUIRE_REAL_CT();
  Progress::set_enabled(false);
  const Volume ct = read_volume(example_ct_path()), labels = read_volume(example_labels_path());
  const auto [l3_lo, l3_hi] = slices_of(labels, 29);   // vertebrae_L3; RAS: k grows towards the head
  ASSERT_GE(l3_hi, l3_lo);
  const int64_t cut = (l3_lo + l3_hi) / 2;
  const Case upper{crop_slices(ct, cut, ct.geometry().dims[2] - 1), crop_slices(labels, cut, ct.geometry().dims[2] - 1)};
  const ScanCoverage c = coverage_of(upper);
  EXPECT_FALSE(c.pelvis_in_view) << c.summary;
  EXPECT_TRUE(c.bottom.cuts_body);
  EXPECT_TRUE(warns_of(c, "no pelvis")) << c.summary;
  EXPECT_NE(c.summary.find("above the pelvis"), std::string::npos) << c.summary;
}

TEST(ScanCoverage, CroppedThroughTheLiversMiddleTheLungsAreGone) {
  PNEUMO_REQUIRE_REAL_CT();
  Progress::set_enabled(false);
  const Volume ct = read_volume(example_ct_path()), labels = read_volume(example_labels_path());
  const auto [liver_lo, liver_hi] = slices_of(labels, 5);
  const int64_t cut = (liver_lo + liver_hi) / 2;
  const Case lower{crop_slices(ct, 0, cut), crop_slices(labels, 0, cut)};
  const ScanCoverage c = coverage_of(lower);
  EXPECT_TRUE(has(c.top.structures, "liver")) << c.summary;
  EXPECT_FALSE(c.lungs_in_view) << c.summary;
  EXPECT_TRUE(warns_of(c, "cuts the liver")) << c.summary;
  EXPECT_TRUE(c.pelvis_in_view);
}

TEST(ScanCoverage, WithoutNamesItStillSaysWhereTheBodyIsCut) {
  PNEUMO_REQUIRE_REAL_CT();
  Progress::set_enabled(false);
  const Volume ct = read_volume(example_ct_path());
  Scene s = default_scene();
  s.roles.source = RoleSource::Auto;
  const RoleVolume rv = assign_roles(s, ct, nullptr);
  const ScanCoverage c = scan_coverage(rv, {});
  EXPECT_TRUE(c.top.cuts_body);
  EXPECT_TRUE(c.bottom.cuts_body);
  EXPECT_TRUE(c.top.structures.empty());
  EXPECT_NE(c.summary.find("top slice cuts the body"), std::string::npos) << c.summary;
}
