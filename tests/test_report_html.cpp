// report.html (report/report_html.h): self-contained (no external references), content present.
#include <gtest/gtest.h>

#include <fstream>

#include "io_test_support.h"
#include "image/png.h"
#include "report/report_html.h"

using namespace pneumo;

TEST(ReportHtml, Base64MatchesRfc4648Vectors) {
  // Compared: the test vectors of RFC 4648 §10, and bytes above 127.
  EXPECT_EQ(base64(""), "");
  EXPECT_EQ(base64("f"), "Zg==");
  EXPECT_EQ(base64("fo"), "Zm8=");
  EXPECT_EQ(base64("foo"), "Zm9v");
  EXPECT_EQ(base64("foob"), "Zm9vYg==");
  EXPECT_EQ(base64("fooba"), "Zm9vYmE=");
  EXPECT_EQ(base64("foobar"), "Zm9vYmFy");
  EXPECT_EQ(base64(std::string("\xff\xfe\x00", 3)), "//4A");
}

TEST(ReportHtml, EmbedsImagesAndPlotsAndReferencesNothingOutside) {
  // Compared: the page against what a reader offline needs: the PNG's bytes embedded as a data URI (its
  // base64 present verbatim), the plot inline, the metrics and scene values shown, markup escaped, and no
  // src= or href= pointing at a file or the network. A missing image is named, not fatal.
  testing_support::ScratchDir dir;
  RgbImage img(4, 3);
  const std::string png = dir.file("view.png");
  write_png(png, img);
  std::ifstream in(png, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());

  ReportContent c;
  c.title = "case <1>";
  c.metrics = {{"converged", true}, {"stop_reason", "converged"}, {"anterior_rise_mm", 19.27},
               {"stage_seconds", {{"solve", 1.5}}}, {"pressure_curve", {{{"pressure_mmhg", 5}, {"cavity_volume_ml", 284}}}}};
  c.scene = {{"load", {{"pressure_mmhg", 12}}}};
  c.plots.push_back({"convergence", "<?xml version=\"1.0\"?><svg xmlns=\"http://www.w3.org/2000/svg\"></svg>"});
  c.images.push_back({"view", png});
  c.images.push_back({"gone", dir.file("missing.png")});
  const std::string html = report_html(c);
  EXPECT_NE(html.find("data:image/png;base64," + base64(bytes)), std::string::npos);
  EXPECT_NE(html.find("<svg xmlns"), std::string::npos);
  EXPECT_EQ(html.find("<?xml"), std::string::npos);   // the prolog is dropped when inlined
  EXPECT_NE(html.find("case &lt;1&gt;"), std::string::npos);
  EXPECT_NE(html.find("19.27"), std::string::npos);
  EXPECT_NE(html.find("load.pressure_mmhg"), std::string::npos);
  EXPECT_NE(html.find("<th>cavity_volume_ml</th>"), std::string::npos);
  EXPECT_NE(html.find("missing: "), std::string::npos);
  EXPECT_EQ(html.find("src=\"file"), std::string::npos);
  EXPECT_EQ(html.find("src=\"http"), std::string::npos);
  EXPECT_EQ(html.find("href="), std::string::npos);
}
