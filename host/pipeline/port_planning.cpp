#include "pipeline/port_planning.h"

#include <algorithm>
#include <cmath>

#include "image/text.h"
#include "render/image_out.h"

namespace pneumo {

namespace {

nlohmann::json vec_json(const Vec3& v) { return {v.x(), v.y(), v.z()}; }

/// A number, or null where it is not defined (no other port; no other labelled structure).
nlohmann::json finite_or_null(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); }

std::string name_of(const std::map<int, std::string>& names, int id) {
  const auto n = names.find(id);
  return n == names.end() || n->second.empty() ? "label " + std::to_string(id) : n->second;
}

/// Perceptually ordered colours from low to high score (viridis' end points and middle, sampled
/// from matplotlib's table): dark purple, teal, yellow.
Rgb score_colour(double s) {
  static const double stops[5][3] = {{68, 1, 84}, {59, 82, 139}, {33, 145, 140}, {94, 201, 98}, {253, 231, 37}};
  const double t = std::clamp(s, 0.0, 1.0) * 4.0;
  const int k = std::min(3, int(t));
  const double f = t - k;
  auto mix = [&](int c) { return uint8_t(std::lround(stops[k][c] + f * (stops[k + 1][c] - stops[k][c]))); };
  return Rgb{mix(0), mix(1), mix(2)};
}

}  // namespace

std::optional<Vec3> skin_point_on_ct(const PointMap& map, const Vec3& skin_mm, const Vec3& inward, double step_mm) {
  const Vec3 u = inward.normalized();
  for (int k = 0; k <= 8; ++k) {
    const MappedPoint back = map.to_original(skin_mm + double(k) * step_mm * u);
    if (back.carried) return back.point_mm;
  }
  return std::nullopt;
}

std::vector<std::optional<Vec3>> candidates_on_ct(const PortRanking& r, const PointMap& map, double step_mm) {
  std::vector<std::optional<Vec3>> out;
  for (const PortCandidate& c : r.candidates) out.push_back(skin_point_on_ct(map, c.skin_mm, c.aim_mm - c.skin_mm, step_mm));
  return out;
}

nlohmann::json port_ranking_json(const PortRanking& r, const PortRankOptions& o, const std::map<int, std::string>& names,
                                 const std::vector<std::optional<Vec3>>& on_ct, const PointMap& map) {
  nlohmann::json j;
  j["target"] = {{"label", o.target_label},
                 {"name", name_of(names, o.target_label)},
                 {"voxels", r.target_voxels},
                 {"surface_voxels", r.surface_voxels},
                 {"exposed_voxels", r.exposed_voxels},
                 {"centroid_deformed_mm", vec_json(r.target_centroid_mm)},
                 {"aim_deformed_mm", vec_json(r.target_aim_mm)}};
  j["options"] = {{"grid_mm", o.grid_mm},
                  {"fov_deg", o.fov_deg},
                  {"eye_depth_mm", o.eye_depth_mm},
                  {"max_wall_mm", o.max_wall_mm},
                  {"skin_hu", o.skin_hu},
                  {"target_samples", o.target_samples},
                  {"other_ports", int(o.other_ports_mm.size())}};
  j["weights"] = {{"visibility", o.weights.visibility},
                  {"clearance", o.weights.clearance},
                  {"distance", o.weights.distance},
                  {"elevation", o.weights.elevation},
                  {"triangulation", o.other_ports_mm.empty() ? 0.0 : o.weights.triangulation}};
  nlohmann::json layers = nlohmann::json::array();
  for (int l : r.wall_layer_labels) layers.push_back({{"label", l}, {"name", name_of(names, l)}});
  j["wall_layer_labels"] = layers;
  nlohmann::json list = nlohmann::json::array();
  int rank = 0, feasible = 0;
  for (std::size_t k = 0; k < r.candidates.size(); ++k) {
    const PortCandidate& c = r.candidates[k];
    nlohmann::json p;
    p["rank"] = c.feasible() ? nlohmann::json(++rank) : nlohmann::json(nullptr);
    p["skin_point_mm"] = on_ct[k] ? vec_json(*on_ct[k]) : nlohmann::json(nullptr);
    p["skin_point_deformed_mm"] = vec_json(c.skin_mm);
    p["feasible"] = c.feasible();
    p["score"] = c.score;
    p["elevation_deg"] = c.elevation_deg;
    if (c.feasible()) {
      ++feasible;
      p["aim_deformed_mm"] = vec_json(c.aim_mm);
      // A path re-aimed at the exposed surface (the one to the centroid was closed): where a port
      // placed here must aim, on the CT as given (the target's point, which travels with it).
      p["reaimed"] = (c.aim_mm - r.target_aim_mm).norm() > 1e-9;
      if (p["reaimed"].get<bool>()) {
        const MappedPoint aim = map.to_original(c.aim_mm);
        p["aim_mm"] = aim.carried ? vec_json(aim.point_mm) : nlohmann::json(nullptr);
      }
      p["visible_fraction"] = c.visible_fraction;
      p["skin_to_target_mm"] = c.skin_to_target_mm;
      p["wall_mm"] = c.wall_mm;
      p["clearance_mm"] = finite_or_null(c.clearance_mm);
      if (c.nearest_label) p["nearest_structure"] = {{"label", c.nearest_label}, {"name", name_of(names, c.nearest_label)}};
      p["spacing_mm"] = finite_or_null(c.spacing_mm);
      p["manipulation_deg"] = finite_or_null(c.manipulation_deg);
      p["terms"] = {{"visibility", c.t_visibility},
                    {"clearance", c.t_clearance},
                    {"distance", c.t_distance},
                    {"elevation", c.t_elevation}};
      if (!o.other_ports_mm.empty()) p["terms"]["triangulation"] = c.t_triangulation;
    } else {
      p["problem"] = port_problem_name(c.problem);
      std::string why;
      switch (c.problem) {
        case PortProblem::NoGas: why = "the path meets no gas before the target"; break;
        case PortProblem::WallTooThick: why = "the gas lies deeper than a trocar reaches"; break;
        case PortProblem::CrossesOrgan: why = "the trocar would cross " + name_of(names, c.blocking_label); break;
        case PortProblem::Blocked:
          why = c.blocking_label ? name_of(names, c.blocking_label) + " lies between the gas and the target"
                                 : "unlabelled tissue lies between the gas and the target";
          break;
        case PortProblem::None: break;
      }
      p["why"] = why;
    }
    list.push_back(p);
  }
  j["feasible_candidates"] = feasible;
  j["candidates"] = list;
  return j;
}

RgbImage port_heat_map(const RenderImage& exterior, const ViewCamera& camera, const PortRanking& r,
                       const std::string& caption, const std::vector<SkinMark>& placed_ports) {
  RgbImage im(exterior.width, exterior.height);
  im.rgb = to_rgb8(exterior);
  const int scale = im.width >= 400 ? 2 : 1;
  // Worst first, so the best lie on top where discs overlap.
  std::vector<const PortCandidate*> order;
  for (const PortCandidate& c : r.candidates) order.push_back(&c);
  std::reverse(order.begin(), order.end());
  for (const PortCandidate* c : order) {
    const std::optional<Eigen::Vector2d> p = visible_on_view(exterior, camera, c->skin_mm);
    if (!p) continue;
    if (!c->feasible()) {
      draw_ring(im, p->x(), p->y(), -1.0, 1.0 * scale, Rgb{90, 90, 90});
      continue;
    }
    draw_ring(im, p->x(), p->y(), -1.0, 3.5 * scale, Rgb{0, 0, 0});
    draw_ring(im, p->x(), p->y(), -1.0, 2.5 * scale, score_colour(c->score));
  }
  int rank = 0;
  for (const PortCandidate& c : r.candidates) {
    if (!c.feasible() || ++rank > 3) break;
    const std::optional<Eigen::Vector2d> p = visible_on_view(exterior, camera, c.skin_mm);
    if (!p) continue;
    draw_ring(im, p->x(), p->y(), 5.0 * scale, 6.0 * scale, Rgb{255, 255, 255});
    draw_text(im, int(p->x() + 7 * scale), int(p->y() - 7 * scale), std::to_string(rank), Rgb{255, 255, 255}, scale);
  }
  // The colour bar: score 0 to 1, bottom right.
  const int bar_w = 100 * scale, bar_h = 6 * scale, x0 = im.width - bar_w - 8 * scale,
            y0 = im.height - bar_h - text_height_px(scale) - 10 * scale;
  for (int x = 0; x < bar_w; ++x) im.fill_rect(x0 + x, y0, 1, bar_h, score_colour(double(x) / double(bar_w - 1)));
  const Rgb white{255, 255, 255};
  draw_text(im, x0, y0 + bar_h + 2 * scale, "0", white, scale);
  draw_text(im, x0 + bar_w - text_width_px("1", scale), y0 + bar_h + 2 * scale, "1", white, scale);
  draw_text(im, x0 + bar_w / 2 - text_width_px("score", scale) / 2, y0 + bar_h + 2 * scale, "score", white, scale);
  draw_marks(im, exterior, camera, caption, placed_ports);   // the ports placed on top of the discs
  return im;
}

}  // namespace pneumo
