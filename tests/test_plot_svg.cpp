// SVG line plots (report/plot_svg.h): ticks, placement on linear and log axes, what is skipped.
#include <gtest/gtest.h>

#include <cmath>
#include <regex>

#include "io_test_support.h"
#include "report/plot_svg.h"

using namespace pneumo;

namespace {

/// The (x, y) pairs of every polyline's points attribute, in order.
std::vector<std::pair<double, double>> polyline_points(const std::string& svg) {
  std::vector<std::pair<double, double>> out;
  const std::regex poly("points=\"([^\"]*)\"");
  for (auto it = std::sregex_iterator(svg.begin(), svg.end(), poly); it != std::sregex_iterator(); ++it) {
    std::istringstream in((*it)[1].str());
    double x, y;
    char comma;
    while (in >> x >> comma >> y) out.push_back({x, y});
  }
  return out;
}

}  // namespace

TEST(PlotSvg, NiceTicksAreOneTwoFiveStepsCoveringTheRange) {
  // Compared: hand-worked tick sets. 0…1 in ~6 steps is 0.2 apart; 0…97 is 20 apart; 3…7.5 is 1 apart.
  EXPECT_EQ(nice_ticks(0, 1), (std::vector<double>{0, 0.2, 0.4, 0.6000000000000001, 0.8, 1}));
  EXPECT_EQ(nice_ticks(0, 97), (std::vector<double>{0, 20, 40, 60, 80}));
  const auto t = nice_ticks(3, 7.5);
  ASSERT_EQ(t.size(), 5u);
  EXPECT_DOUBLE_EQ(t.front(), 3);
  EXPECT_DOUBLE_EQ(t.back(), 7);
  EXPECT_EQ(nice_ticks(2, 2), (std::vector<double>{2}));
}

TEST(PlotSvg, PointsLandInsideThePlotAndKeepTheirOrder) {
  // Compared: the drawn coordinates against the plot frame (640×400, margins 70/20/40/50): a rising series
  // goes left to right and upwards (SVG y grows downwards); every point lies inside the frame.
  PlotSeries s{"v", {0, 1, 2, 3}, {0, 10, 20, 30}};
  PlotOptions o;
  o.title = "t";
  const std::string svg = line_plot_svg({s}, o);
  const auto p = polyline_points(svg);
  ASSERT_EQ(p.size(), 4u);
  for (std::size_t i = 0; i < p.size(); ++i) {
    EXPECT_GE(p[i].first, 70 - 1e-9);
    EXPECT_LE(p[i].first, 620 + 1e-9);
    EXPECT_GE(p[i].second, 40 - 1e-9);
    EXPECT_LE(p[i].second, 350 + 1e-9);
    if (i) {
      EXPECT_GT(p[i].first, p[i - 1].first);
      EXPECT_LT(p[i].second, p[i - 1].second);
    }
  }
  EXPECT_NEAR(p.front().first, 70, 0.06);
  EXPECT_NEAR(p.back().first, 620, 0.06);
}

TEST(PlotSvg, LogAxisSpacesDecadesEquallyAndSkipsWhatItCannotDraw) {
  // Compared: on a log axis 1e-1, 1e-2, 1e-3 are equally spaced (to the 0.1 px the file rounds to); a zero,
  // a negative and a NaN are left out and split the line into separate polylines.
  PlotSeries s{"r", {0, 1, 2, 3, 4, 5, 6}, {1e-1, 1e-2, 1e-3, 0.0, 1e-4, NAN, 1e-5}};
  PlotOptions o;
  o.log_y = true;
  const std::string svg = line_plot_svg({s}, o);
  const auto p = polyline_points(svg);
  ASSERT_EQ(p.size(), 3u);   // the single points 1e-4 and 1e-5 make no line
  EXPECT_NEAR(p[1].second - p[0].second, p[2].second - p[1].second, 0.15);
  EXPECT_EQ(testing_support::count_occurrences(svg, "<polyline"), 1);
  EXPECT_EQ(svg.find("nan"), std::string::npos);
  EXPECT_EQ(svg.find("inf"), std::string::npos);
}

TEST(PlotSvg, TextIsEscapedAndStackedPanelsAddUp) {
  // Compared: markup in labels is escaped; two stacked panels of 400 and 300 px make one 700 px document
  // holding both.
  PlotSeries s{"a<b", {0, 1}, {1, 2}};
  PlotOptions a;
  a.title = "x & y";
  PlotOptions b;
  b.height_px = 300;
  const std::string one = line_plot_svg({s, s}, a);
  EXPECT_NE(one.find("x &amp; y"), std::string::npos);
  EXPECT_NE(one.find("a&lt;b"), std::string::npos);   // in the legend
  const std::string both = stack_svg({one, line_plot_svg({s}, b)});
  EXPECT_NE(both.find("height=\"700\""), std::string::npos);
  EXPECT_EQ(testing_support::count_occurrences(both, "<svg "), 3);
  EXPECT_NE(both.find("y=\"400\""), std::string::npos);
}
