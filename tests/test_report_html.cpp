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
  c.images.push_back({"view", png, ""});
  c.images.push_back({"gone", dir.file("missing.png"), ""});
  const std::string html = report_html(c);
  EXPECT_NE(html.find("data:image/png;base64," + base64(bytes)), std::string::npos);
  EXPECT_NE(html.find("<svg xmlns"), std::string::npos);
  EXPECT_EQ(html.find("<?xml"), std::string::npos);   // the prolog is dropped when inlined
  EXPECT_NE(html.find("case &lt;1&gt;"), std::string::npos);
  EXPECT_NE(html.find("19.27"), std::string::npos);
  EXPECT_NE(html.find("load.pressure_mmhg"), std::string::npos);
  // The curve's cavity is the mesh's estimate at each pressure (simulate.cpp), named so.
  EXPECT_NE(html.find("<th>Insufflated cavity (mesh) (ml)</th>"), std::string::npos);
  EXPECT_NE(html.find("missing: "), std::string::npos);
  EXPECT_EQ(html.find("src=\"file"), std::string::npos);
  EXPECT_EQ(html.find("src=\"http"), std::string::npos);
  EXPECT_EQ(html.find("href="), std::string::npos);
}

TEST(ReportHtml, ReadsInTheOrderAReaderAsks) {
  // Compared: what a surgeon-researcher's page needs, in order: the outcome in words (not "Converged
  // (converged)"), then the views with their captions, the fly-through, the slices, the solver, the
  // time in pipeline order (roles before mesh before solve ..., not alphabetical), every metric by name
  // and unit, a fraction shown in %, and the scene folded away last.
  testing_support::ScratchDir dir;
  RgbImage img(4, 3);
  write_png(dir.file("v.png"), img);
  ReportContent c;
  c.title = "case";
  c.description = "a test case";
  c.metrics = {{"converged", true},         {"stop_reason", "converged"},   {"steps", 120},
               {"anterior_rise_mm", 43.0},  {"cavity_volume_ml", 1475.0},
               {"cavity_outside_largest_piece_fraction", 0.005},
               {"some_new_length_mm", 2.5},
               {"stage_seconds", {{"warp", 2.0}, {"mesh", 1.0}, {"roles", 0.5}, {"solve", 9.0}, {"total", 13.0}}}};
  c.scene = {{"load", {{"pressure_mmhg", 12}}}};
  c.views.push_back({"umbilical", dir.file("v.png"), "Port on the skin at (0, 100, 0) mm, aimed at liver"});
  c.images.push_back({"Slices before and after", dir.file("v.png"), "the gas in blue"});
  const std::string html = report_html(c);
  EXPECT_EQ(html.find("Converged (converged)"), std::string::npos);
  EXPECT_NE(html.find("Converged after 120 solver steps"), std::string::npos);
  EXPECT_NE(html.find("a test case"), std::string::npos);
  EXPECT_NE(html.find("aimed at liver</figcaption>"), std::string::npos);
  const auto at = [&](const std::string& s) { return html.find(s); };
  EXPECT_LT(at("<h2>Views</h2>"), at("<h2>Before and after</h2>"));
  EXPECT_LT(at("<h2>Before and after</h2>"), at("<h2>Where the time went</h2>"));
  EXPECT_LT(at("<h2>Where the time went</h2>"), at("<h2>Metrics</h2>"));
  EXPECT_LT(at("<h2>Metrics</h2>"), at("<details><summary>Scene"));
  EXPECT_LT(at("<td>roles</td>"), at("<td>mesh</td>"));
  EXPECT_LT(at("<td>mesh</td>"), at("<td>solve</td>"));
  EXPECT_LT(at("<td>solve</td>"), at("<td>warp</td>"));
  EXPECT_NE(at("<td>Anterior rise of the abdominal wall</td><td>43 mm</td>"), std::string::npos);
  EXPECT_NE(at("<td>Cavity outside its largest piece</td><td>0.5 %</td>"), std::string::npos);
  EXPECT_NE(at("<td>Some new length</td><td>2.5 mm</td>"), std::string::npos);   // unlisted: named from its key
  EXPECT_EQ(at("<td>anterior_rise_mm</td>"), std::string::npos);                  // no raw key as a name
}

TEST(ReportHtml, PlaysAFlyThroughFromItsStrip) {
  // Compared: the strip's bytes embedded once as a JPEG, a CSS animation that steps through exactly
  // `frames` positions of one frame's width (2× the strip's frame: the player shows it enlarged) at the
  // path's frame rate, the MP4 beside the report linked relatively, and no script on the page.
  testing_support::ScratchDir dir;
  RgbImage strip(3 * 40, 30);
  write_jpeg(dir.file("f_strip.jpg"), strip, 85);
  std::ifstream in(dir.file("f_strip.jpg"), std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  ReportContent c;
  ReportAnimation a;
  a.title = "Fly-through liver";
  a.strip_path = dir.file("f_strip.jpg");
  a.frames = 3;
  a.frame_width = 40;
  a.frame_height = 30;
  a.fps = 6;
  a.video_link = "flythrough/liver.mp4";
  c.flythroughs.push_back(a);
  const std::string html = report_html(c);
  const std::string uri = "data:image/jpeg;base64," + base64(bytes);
  ASSERT_NE(html.find(uri), std::string::npos);
  EXPECT_EQ(html.find(uri, html.find(uri) + 1), std::string::npos);   // once, shared by player and filmstrip
  EXPECT_NE(html.find("to{background-position:-240px 0}"), std::string::npos);   // 3 frames × 80 px
  EXPECT_NE(html.find("width:80px;height:60px"), std::string::npos);
  EXPECT_NE(html.find("0.5s steps(3) infinite"), std::string::npos);             // 3 frames at 6/s
  EXPECT_NE(html.find("<a href=\"flythrough/liver.mp4\">"), std::string::npos);
  EXPECT_EQ(html.find("<script"), std::string::npos);
}
