#pragma once
// report.html: one self-contained page a user opens offline (images embedded as data URIs, plots
// inline as SVG, the fly-through as an animated strip in CSS; no script, nothing fetched). In the
// order a reader asks: did it work and what came out, what the laparoscope sees, the body before
// and after, how the solver got there, where the time went, every metric by name and unit, and the
// scene folded away at the end.
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace pneumo {

struct ReportImage {
  std::string title;
  std::string path;      // a PNG (or JPEG) file; embedded
  std::string caption;   // what it shows and how it was taken (port, scope, field of view)
};

struct ReportPlot {
  std::string title;
  std::string svg;       // an SVG document; inlined
};

/// A fly-through: its frames side by side in one image (render's flythrough/<path>_strip.jpg),
/// played by stepping a CSS background through them.
struct ReportAnimation {
  std::string title;
  std::string strip_path;      // embedded
  int frames = 0;
  int frame_width = 0, frame_height = 0;   // one frame in the strip, px
  double fps = 24.0;
  std::string caption;
  std::string video_link;      // relative link to the full-size MP4 beside the report (empty: none)
};

struct ReportContent {
  std::string title;
  std::string description;   // the scene's description (may be empty)
  nlohmann::json scene;      // the resolved scene (Scene::echo())
  nlohmann::json metrics;    // metrics.json
  std::vector<ReportImage> views;        // laparoscope views and exterior views, with captions
  std::vector<ReportAnimation> flythroughs;
  std::vector<ReportImage> images;       // slices, roles
  std::vector<ReportPlot> plots;
};

/// RFC 4648 base64 of raw bytes.
std::string base64(const std::string& bytes);

/// The page as a string. Image files that cannot be read are listed as missing, not fatal.
std::string report_html(const ReportContent& content);

}  // namespace pneumo
