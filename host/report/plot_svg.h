#pragma once
// Line plots as SVG: convergence histories and pressure–volume curves, as files and inline in
// report.html (text, so the report stays one self-contained page and the plots stay sharp).
#include <string>
#include <vector>

namespace pneumo {

struct PlotSeries {
  std::string name;
  std::vector<double> x, y;
  std::string colour = "#1f77b4";
  bool markers = false;        // a dot on each point (few points: a measured curve)
};

struct PlotOptions {
  std::string title, x_label, y_label;
  bool log_y = false;          // decades; points with y ≤ 0 or non-finite are left out
  int width_px = 640, height_px = 400;
};

/// Axis ticks: "nice" values (1, 2, 5 × 10ⁿ) covering [lo, hi], about `target` of them.
std::vector<double> nice_ticks(double lo, double hi, int target = 6);

/// An SVG document (UTF-8) of the series over shared axes, with a legend when there are several.
/// Points that cannot be drawn (non-finite, or ≤ 0 on a log axis) are skipped, breaking the line.
std::string line_plot_svg(const std::vector<PlotSeries>& series, const PlotOptions& opt);

/// Several SVG documents from line_plot_svg stacked top to bottom into one.
std::string stack_svg(const std::vector<std::string>& panels);

}  // namespace pneumo
