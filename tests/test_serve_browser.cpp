// `pneumo serve`'s page in a real browser: tests/python/serve_page.py drives headless Chromium with
// Selenium (Debian's chromium, chromium-driver and python3-selenium, installed by
// scripts/install_deps.sh) through the page on the small phantom at `preview`: a port placed by a
// click on the skin, the laparoscope's view, the pressure slider moved down, the view changed and the
// status at the new pressure, a screenshot. Skipped, saying why, only where Chromium cannot start.
#include <gtest/gtest.h>

#include <cstdlib>
#include <fstream>
#include <nlohmann/json.hpp>

#include "cli_test_support.h"
#include "core/progress.h"
#include "phantom/phantom.h"

using namespace pneumo;
using testing_support::ScratchDir;

TEST(ServeBrowser, SeleniumPlacesAPortAndMovesThePressure) {
  ScratchDir dir;
  Progress::set_enabled(false);
  write_phantom_case(make_phantom(PhantomSize::Small), PhantomSize::Small, dir.path().string());
  nlohmann::json j = nlohmann::json::parse(testing_support::slurp(dir.file("scene.json")));
  j["preset"] = "preview";
  std::ofstream(dir.file("serve_scene.json")) << j.dump(2);
  const char* keep = std::getenv("PNEUMO_KEEP_SERVE_SCREENSHOT");
  const std::string shot = keep ? keep : dir.file("serve.png");
  const testing_support::CliResult r = testing_support::run_shell(
      std::string("timeout 600 ") + PNEUMO_VTK_PYTHON + " " PNEUMO_SOURCE_DIR "/tests/python/serve_page.py " PNEUMO_CLI_PATH " " +
      dir.file("serve_scene.json") + " " + dir.path().string() + " " + shot);
  if (r.code == 77) GTEST_SKIP() << r.out;
  EXPECT_EQ(r.code, 0) << r.out << r.err;
  EXPECT_TRUE(std::ifstream(shot).good()) << "the screenshot";
}
