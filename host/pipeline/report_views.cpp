#include "pipeline/report_views.h"

#include <cstdio>

#include "domain/types.h"

namespace pneumo {
namespace {

std::string mm(const Vec3& v) {
  char b[96];
  std::snprintf(b, sizeof b, "(%.0f, %.0f, %.0f) mm", v.x(), v.y(), v.z());
  return b;
}

std::string plain(double d) {
  char b[32];
  std::snprintf(b, sizeof b, "%g", d);
  return b;
}

std::string degrees(double d) { return plain(d) + "°"; }

/// "30° oblique scope, rolled 15°, 70° pinhole field of view".
std::string optics_text(const Optics& o) {
  std::string s = o.oblique_deg == 0.0 ? "0° (straight) scope" : degrees(o.oblique_deg) + " oblique scope";
  if (o.roll_deg != 0.0) s += ", rolled " + degrees(o.roll_deg);
  return s + ", " + degrees(o.fov_deg) + " " + enum_name(o.lens) + " field of view";
}

std::string label_text(int id, const std::map<int, std::string>& names) {
  const auto it = names.find(id);
  return it == names.end() ? "label " + std::to_string(id) : it->second + " (label " + std::to_string(id) + ")";
}

std::string exterior_caption(const nlohmann::json& v) {
  const std::string& name = v.at("name").get_ref<const std::string&>();
  const std::string side = name == "exterior_left" ? "the patient's left" : "the front";
  const bool both = v.contains("panels") && v["panels"].size() == 2;
  std::string s = "The skin (the surface near −500 HU) seen from " + side + ", " +
                  (both ? "before inflation (left) and after it (right) under one camera, so the rise of the "
                          "dome reads between the panels."
                        : "as rendered.");
  const nlohmann::json& marked = v.value("ports_marked", nlohmann::json());
  const nlohmann::json& after = both && marked.is_object() ? marked.value("after", nlohmann::json()) : marked;
  if (after.is_array() && !after.empty()) {
    s += " Ports marked in yellow:";
    for (std::size_t i = 0; i < after.size(); ++i) s += (i ? ", " : " ") + after[i].get<std::string>();
    s += ".";
  }
  return s;
}

}  // namespace

std::string view_caption(const std::string& name, const ViewSettings& r, const std::map<int, std::string>& label_names) {
  for (const Port& p : r.ports) {
    if (p.name != name) continue;
    const std::string target = p.target_mm ? "the point " + mm(*p.target_mm) : label_text(*p.target_label, label_names);
    char depth[48];
    std::snprintf(depth, sizeof depth, "%.0f mm", p.insertion_mm);
    return "Port on the skin at " + mm(p.skin_point_mm) + " (CT before inflation, carried with the wall), aimed at " +
           target + "; tip " + depth + " inside; " + optics_text(p.optics) + ".";
  }
  for (const Camera& c : r.cameras)
    if (c.name == name)
      return "Camera at " + mm(c.position_mm) + " looking at " + mm(c.look_at_mm) + "; " + optics_text(c.optics) + ".";
  return "";
}

void add_rendered_views(ReportContent& c, const nlohmann::json& render_report, const ViewSettings& r,
                        const std::map<int, std::string>& label_names, const std::filesystem::path& out_dir) {
  for (const nlohmann::json& v : render_report.value("views", nlohmann::json::array())) {
    const std::string name = v.at("name").get<std::string>();
    const bool exterior = v.value("preset", std::string()) == "skin";
    c.views.push_back({exterior ? "Exterior, " + std::string(name == "exterior_left" ? "left" : "anterior") : name,
                       (out_dir / v.at("file").get<std::string>()).string(),
                       exterior ? exterior_caption(v) : view_caption(name, r, label_names)});
  }
  for (const nlohmann::json& p : render_report.value("paths", nlohmann::json::array())) {
    if (!p.contains("strip")) continue;
    const std::string name = p.at("name").get<std::string>();
    ReportAnimation a;
    a.title = "Fly-through " + name;
    a.strip_path = (out_dir / p["strip"].at("file").get<std::string>()).string();
    a.frames = p.at("frames").get<int>();
    a.frame_width = p["strip"].at("frame_px").at(0).get<int>();
    a.frame_height = p["strip"].at("frame_px").at(1).get<int>();
    a.fps = r.video_fps;
    for (const CameraPath& cp : r.paths)
      if (cp.name == name)
        a.caption = std::to_string(a.frames) + " frames through " + std::to_string(cp.keyframes.size()) +
                    " keyframes, " + optics_text(cp.optics) + "; played here at " + plain(a.fps) +
                    " frames/s, reduced, below it frame by frame.";
    if (p.contains("mp4")) a.video_link = p["mp4"].get<std::string>();
    c.flythroughs.push_back(a);
  }
}

}  // namespace pneumo
