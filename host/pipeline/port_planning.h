#pragma once
// Port planning on a solved, warped case (docs/ports.md): the ranking of plan/port_ranking.h
// with its candidates carried back to the CT as given (where a plan's ports are written: they travel
// with the skin), as the JSON table `pneumo ports` writes and the page reads, and as a heat map on the
// exterior view of the inflated body.
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "image/image.h"
#include "pipeline/exterior_views.h"
#include "plan/port_ranking.h"
#include "render/camera_model.h"
#include "render/render_settings.h"
#include "warp/point_map.h"

namespace pneumo {

/// The point on the CT as given whose image is the deformed skin point `skin_mm`: the first point a
/// little deeper along `inward` (up to 8 steps of `step_mm`, half a voxel) that a tetrahedron
/// carries. A skin point found on the deformed image (the first surface a ray meets, where the
/// skin's opacity begins; the candidates' first voxel at the skin's HU) lies within a voxel of the
/// mesh's own boundary. nullopt when none is carried.
std::optional<Vec3> skin_point_on_ct(const PointMap& map, const Vec3& skin_mm, const Vec3& inward, double step_mm);

/// Each candidate's skin point on the CT as given (skin_point_on_ct, inward along its path), in the
/// ranking's order: where a port placed there is written, and from where it travels with the skin.
std::vector<std::optional<Vec3>> candidates_on_ct(const PortRanking& r, const PointMap& map, double step_mm);

/// The ranked table: the target (id, name, centroid), the options and weights, and each candidate
/// (best first) with its skin point on the CT as given (`on_ct`, from candidates_on_ct) and deformed,
/// its score, terms and measures, or why it cannot serve. `names` names the labels (empty: "label
/// N"); `map` carries a re-aimed path's aim back to the CT.
nlohmann::json port_ranking_json(const PortRanking& r, const PortRankOptions& o, const std::map<int, std::string>& names,
                                 const std::vector<std::optional<Vec3>>& on_ct, const PointMap& map);

/// The exterior view (a render of the skin, with `camera`) with every candidate drawn as a disc in
/// the colour of its score (small grey dots: infeasible), the best three ringed and numbered, the
/// ports already placed marked, a colour bar and `caption`.
RgbImage port_heat_map(const RenderImage& exterior, const ViewCamera& camera, const PortRanking& r,
                       const std::string& caption, const std::vector<SkinMark>& placed_ports);

}  // namespace pneumo
