// report.html as a reader sees it: `pneumo run` on the small phantom with a port, a camera, a
// fly-through and the exterior views, then headless Chromium (Debian's chromium, installed by
// scripts/install_deps.sh) loads the page from disk and takes a screenshot. Skipped, saying why,
// only where Chromium is missing or cannot start here.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <string>

#include "cli_test_support.h"
#include "core/progress.h"
#include "phantom/phantom.h"
#include "pipeline/run.h"
#include "scene/scene.h"
#include "stb_image_support.h"

using namespace pneumo;
using testing_support::ScratchDir;
namespace fs = std::filesystem;

namespace {

// One browser process: no sandbox (CI runs as root), no GPU, its own profile, sRGB so that image
// pixels reach the screenshot unchanged, and a hard time limit so a stuck browser fails the test.
std::string chromium(const ScratchDir& dir, const std::string& args) {
  return "timeout 120 chromium --headless --no-sandbox --disable-gpu --disable-dev-shm-usage --hide-scrollbars "
         "--force-color-profile=srgb --force-device-scale-factor=1 --user-data-dir=" +
         dir.file("profile") + " " + args;
}

struct Pixels {
  int width = 0, height = 0;
  std::vector<unsigned char> rgb;
  const unsigned char* at(int x, int y) const { return &rgb[3 * (std::size_t(y) * width + x)]; }
};

Pixels load_png(const std::string& path) {
  Pixels p;
  int c = 0;
  unsigned char* px = stbi_load(path.c_str(), &p.width, &p.height, &c, 3);
  if (!px) return p;
  p.rgb.assign(px, px + std::size_t(3) * p.width * p.height);
  stbi_image_free(px);
  return p;
}

}  // namespace

TEST(ReportBrowser, ChromiumShowsTheViewsTheSkinAndTheFlyThrough) {
  // Compared: what the page must show a reader, in the browser's own rendering. The DOM Chromium built
  // holds every figure (4 views with captions: port, camera, two exterior; the slices and roles), the
  // fly-through player and no script; in the screenshot the port's yellow ring on the exterior view is
  // visible (the mark's exact colour, so the image is shown unscaled and unaltered), the skin-coloured
  // body covers a large area (two exterior views, before and after: the surface rendering, not the
  // black-and-speckle CT-Air view it replaced), and the page is not blank.
  ScratchDir dir;
  if (testing_support::run_shell("command -v chromium").code != 0)
    GTEST_SKIP() << "chromium is not installed (scripts/install_deps.sh installs it)";
  const testing_support::CliResult probe =
      testing_support::run_shell(chromium(dir, "--dump-dom 'data:text/html,<p>ready</p>'"));
  if (probe.code != 0 || probe.out.find("ready") == std::string::npos)
    GTEST_SKIP() << "chromium cannot start here (exit " << probe.code << "): "
                 << probe.err.substr(0, std::min<std::size_t>(probe.err.size(), 400));

  Progress::set_enabled(false);
  write_phantom_case(make_phantom(PhantomSize::Small), PhantomSize::Small, dir.path().string());
  Scene scene = load_scene(dir.file("scene.json"));
  scene.render.width = 320;
  scene.render.height = 240;
  CameraPath path;
  path.name = "up_the_abdomen";
  path.frames = 6;
  path.keyframes = {{Vec3(0, 96, -90), Vec3(20, 80, 40)}, {Vec3(0, 96, -50), Vec3(20, 80, 60)}};
  scene.render.paths.push_back(path);
  RunOptions o;
  o.out_dir = dir.file("run");
  ASSERT_TRUE(run_pipeline(scene, o).converged);
  const fs::path report = fs::path(o.out_dir) / "report.html";
  ASSERT_TRUE(fs::exists(fs::path(o.out_dir) / "flythrough" / "up_the_abdomen_strip.jpg"));

  const testing_support::CliResult dom = testing_support::run_shell(chromium(dir, "--dump-dom file://" + report.string()));
  ASSERT_EQ(dom.code, 0) << dom.err;
  EXPECT_EQ(testing_support::count_occurrences(dom.out, "<figcaption>"), 8) << "4 views, the fly-through, the slices, the roles, the plot";
  EXPECT_EQ(testing_support::count_occurrences(dom.out, "<img "), 6) << "the port, the camera, 2 exterior views, the slices, the roles";
  EXPECT_EQ(testing_support::count_occurrences(dom.out, "class=\"strip0 player\""), 1);
  EXPECT_NE(dom.out.find("Port on the skin at (0, 110, -20) mm"), std::string::npos);
  EXPECT_NE(dom.out.find("Ports marked in yellow: umbilical_port."), std::string::npos);
  EXPECT_EQ(testing_support::count_occurrences(dom.out, "<script"), 0);

  const std::string shot = dir.file("report.png");
  const testing_support::CliResult r =
      testing_support::run_shell(chromium(dir, "--window-size=1280,7000 --screenshot=" + shot + " file://" + report.string()));
  ASSERT_EQ(r.code, 0) << r.err;
  if (const char* keep = std::getenv("PNEUMO_KEEP_REPORT_SCREENSHOT")) fs::copy_file(shot, keep, fs::copy_options::overwrite_existing);
  const Pixels p = load_png(shot);
  ASSERT_EQ(p.width, 1280);
  ASSERT_EQ(p.height, 7000);
  int64_t yellow = 0, skin = 0, ink = 0;
  for (int y = 0; y < p.height; ++y)
    for (int x = 0; x < p.width; ++x) {
      const unsigned char* c = p.at(x, y);
      yellow += c[0] == 255 && c[1] == 230 && c[2] == 0;
      // The skin's colour (177, 122, 101) under any shading: red over green over blue, in proportion.
      skin += c[0] > 40 && c[0] > c[1] + 15 && c[1] > c[2] && c[2] > 0.4 * c[0] && c[0] < 250;
      ink += c[0] + c[1] + c[2] < 600;
    }
  EXPECT_GE(yellow, 40) << "the port's ring on the exterior views (before and after, two sides)";
  EXPECT_GE(skin, 20000) << "the skin of the exterior views";
  EXPECT_GE(ink, int64_t(p.width) * p.height / 20) << "a page of text alone is nearly white";
}
