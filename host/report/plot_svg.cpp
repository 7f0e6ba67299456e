#include "report/plot_svg.h"
#include "report/markup.h"

#include <algorithm>
#include <cstdlib>
#include <cmath>
#include <cstdio>
#include <sstream>

namespace pneumo {

namespace {

std::string number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

std::string fixed(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.1f", v);
  return buf;
}

bool drawable(double x, double y, bool log_y) { return std::isfinite(x) && std::isfinite(y) && (!log_y || y > 0.0); }

}  // namespace

std::vector<double> nice_ticks(double lo, double hi, int target) {
  if (!(hi > lo)) return {lo};
  const double raw = (hi - lo) / std::max(1, target);
  const double decade = std::pow(10.0, std::floor(std::log10(raw)));
  double step = decade;
  for (double m : {1.0, 2.0, 5.0, 10.0})
    if (m * decade >= raw) {
      step = m * decade;
      break;
    }
  std::vector<double> ticks;
  for (double t = std::ceil(lo / step - 1e-9) * step; t <= hi + 1e-9 * step; t += step)
    ticks.push_back(std::abs(t) < 1e-12 * step ? 0.0 : t);
  return ticks;
}

std::string line_plot_svg(const std::vector<PlotSeries>& series, const PlotOptions& opt) {
  // Data range over the drawable points.
  double x0 = INFINITY, x1 = -INFINITY, y0 = INFINITY, y1 = -INFINITY;
  for (const auto& s : series)
    for (std::size_t i = 0; i < std::min(s.x.size(), s.y.size()); ++i) {
      if (!drawable(s.x[i], s.y[i], opt.log_y)) continue;
      const double y = opt.log_y ? std::log10(s.y[i]) : s.y[i];
      x0 = std::min(x0, s.x[i]);
      x1 = std::max(x1, s.x[i]);
      y0 = std::min(y0, y);
      y1 = std::max(y1, y);
    }
  if (!std::isfinite(x0)) x0 = 0, x1 = 1, y0 = 0, y1 = 1;
  if (x1 == x0) x0 -= 0.5, x1 += 0.5;
  if (opt.log_y) {
    y0 = std::floor(y0);
    y1 = std::max(std::ceil(y1), y0 + 1);
  } else {
    if (y1 == y0) y0 -= 0.5, y1 += 0.5;
    const double pad = 0.05 * (y1 - y0);
    y0 = y0 >= 0 && y0 - pad < 0 ? 0.0 : y0 - pad;
    y1 += pad;
  }
  const double W = opt.width_px, H = opt.height_px;
  const double left = 70, right = 20, top = opt.title.empty() ? 20 : 40, bottom = 50;
  const double pw = W - left - right, ph = H - top - bottom;
  auto px = [&](double x) { return left + (x - x0) / (x1 - x0) * pw; };
  auto py = [&](double y) { return top + (1.0 - ((opt.log_y ? std::log10(y) : y) - y0) / (y1 - y0)) * ph; };

  std::ostringstream o;
  o << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << W << "\" height=\"" << H << "\" viewBox=\"0 0 " << W
    << " " << H << "\" font-family=\"sans-serif\" font-size=\"12\">\n";
  o << "<rect x=\"0\" y=\"0\" width=\"" << W << "\" height=\"" << H << "\" fill=\"white\"/>\n";
  if (!opt.title.empty())
    o << "<text x=\"" << W / 2 << "\" y=\"22\" text-anchor=\"middle\" font-size=\"14\">" << escape_markup(opt.title)
      << "</text>\n";
  // Grid and ticks.
  for (double t : nice_ticks(x0, x1)) {
    o << "<line x1=\"" << fixed(px(t)) << "\" y1=\"" << top << "\" x2=\"" << fixed(px(t)) << "\" y2=\"" << top + ph
      << "\" stroke=\"#e5e5e5\"/>\n";
    o << "<text x=\"" << fixed(px(t)) << "\" y=\"" << top + ph + 16 << "\" text-anchor=\"middle\">" << number(t)
      << "</text>\n";
  }
  std::vector<double> yt;
  if (opt.log_y) {
    const int every = std::max(1, int(std::ceil((y1 - y0) / 8.0)));
    for (int e = int(y0); e <= int(y1); e += every) yt.push_back(std::pow(10.0, e));
  } else {
    yt = nice_ticks(y0, y1);
  }
  for (double t : yt) {
    const double y = py(t);
    o << "<line x1=\"" << left << "\" y1=\"" << fixed(y) << "\" x2=\"" << left + pw << "\" y2=\"" << fixed(y)
      << "\" stroke=\"#e5e5e5\"/>\n";
    o << "<text x=\"" << left - 6 << "\" y=\"" << fixed(y + 4) << "\" text-anchor=\"end\">" << number(t) << "</text>\n";
  }
  o << "<rect x=\"" << left << "\" y=\"" << top << "\" width=\"" << pw << "\" height=\"" << ph
    << "\" fill=\"none\" stroke=\"#333\"/>\n";
  o << "<text x=\"" << left + pw / 2 << "\" y=\"" << H - 12 << "\" text-anchor=\"middle\">" << escape_markup(opt.x_label)
    << "</text>\n";
  o << "<text transform=\"translate(16," << top + ph / 2 << ") rotate(-90)\" text-anchor=\"middle\">"
    << escape_markup(opt.y_label) << "</text>\n";
  // Series: one polyline per run of drawable points.
  for (const auto& s : series) {
    std::ostringstream run;
    int in_run = 0;
    auto flush = [&] {
      if (in_run > 1)
        o << "<polyline fill=\"none\" stroke=\"" << s.colour << "\" stroke-width=\"1.5\" points=\"" << run.str()
          << "\"/>\n";
      run.str("");
      in_run = 0;
    };
    for (std::size_t i = 0; i < std::min(s.x.size(), s.y.size()); ++i) {
      if (!drawable(s.x[i], s.y[i], opt.log_y)) {
        flush();
        continue;
      }
      run << (in_run ? " " : "") << fixed(px(s.x[i])) << "," << fixed(py(s.y[i]));
      ++in_run;
      if (s.markers)
        o << "<circle cx=\"" << fixed(px(s.x[i])) << "\" cy=\"" << fixed(py(s.y[i])) << "\" r=\"3\" fill=\""
          << s.colour << "\"/>\n";
    }
    flush();
  }
  if (series.size() > 1)
    for (std::size_t k = 0; k < series.size(); ++k) {
      const double y = top + 14 + 16 * double(k);
      o << "<line x1=\"" << left + pw - 150 << "\" y1=\"" << y - 4 << "\" x2=\"" << left + pw - 130 << "\" y2=\""
        << y - 4 << "\" stroke=\"" << series[k].colour << "\" stroke-width=\"2\"/>\n";
      o << "<text x=\"" << left + pw - 124 << "\" y=\"" << y << "\">" << escape_markup(series[k].name) << "</text>\n";
    }
  o << "</svg>\n";
  return o.str();
}

std::string stack_svg(const std::vector<std::string>& panels) {
  // Each panel keeps its own <svg> element, placed by x/y inside the outer one.
  auto attribute = [](const std::string& svg, const std::string& name) {
    const std::size_t at = svg.find(" " + name + "=\"");
    return at == std::string::npos ? 0.0 : std::atof(svg.c_str() + at + name.size() + 3);
  };
  double width = 0, height = 0;
  std::string body;
  for (const std::string& p : panels) {
    const std::size_t open = p.find("<svg ");
    if (open == std::string::npos) continue;
    body += p.substr(0, open) + "<svg x=\"0\" y=\"" + number(height) + "\" " + p.substr(open + 5);
    width = std::max(width, attribute(p, "width"));
    height += attribute(p, "height");
  }
  return "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" + number(width) + "\" height=\"" + number(height) +
         "\" viewBox=\"0 0 " + number(width) + " " + number(height) + "\">\n" + body + "</svg>\n";
}

}  // namespace pneumo
