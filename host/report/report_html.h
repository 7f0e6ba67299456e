#pragma once
// report.html: one self-contained page a user opens offline (images embedded as data URIs, plots
// inline as SVG): the case, its parameters, the stage timings, the metrics, the plots and the images.
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace pneumo {

struct ReportImage {
  std::string title;
  std::string path;      // a PNG file; embedded
};

struct ReportPlot {
  std::string title;
  std::string svg;       // an SVG document; inlined
};

struct ReportContent {
  std::string title;
  nlohmann::json scene;      // the resolved scene (Scene::echo())
  nlohmann::json metrics;    // metrics.json
  std::vector<ReportPlot> plots;
  std::vector<ReportImage> images;
};

/// RFC 4648 base64 of raw bytes.
std::string base64(const std::string& bytes);

/// The page as a string. Image files that cannot be read are listed as missing, not fatal.
std::string report_html(const ReportContent& content);

}  // namespace pneumo
