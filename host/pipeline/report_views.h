#pragma once
// The report's views and fly-throughs, each with a caption that says what it shows and how it was
// taken (the port's skin point and target, the scope's angle and roll, the lens and its field of
// view; for the exterior views, what is before and what after), from what render_volumes wrote into
// render.json and the scene's render section.
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <string>

#include "report/report_html.h"
#include "render/view_settings.h"

namespace pneumo {

/// Fills c.views and c.flythroughs from `render_report` (render.json's object; files relative to
/// `out_dir`). `label_names` names a port's target label where it is known.
void add_rendered_views(ReportContent& c, const nlohmann::json& render_report, const ViewSettings& r,
                        const std::map<int, std::string>& label_names, const std::filesystem::path& out_dir);

/// The caption of one laparoscope view, port or camera, or "" when `name` is neither.
std::string view_caption(const std::string& name, const ViewSettings& r, const std::map<int, std::string>& label_names);

}  // namespace pneumo
