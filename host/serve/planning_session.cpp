#include "serve/planning_session.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

#include "core/error.h"
#include "core/log.h"
#include "core/units.h"
#include "image/png.h"
#include "mesh/deformation_file.h"
#include "pipeline/exterior_views.h"
#include "pipeline/port_planning.h"
#include "pipeline/render_scene.h"
#include "pipeline/scene_stages.h"
#include "pipeline/warp_stage.h"
#include "render/image_out.h"
#include "render/poses.h"
#include "report/slices.h"

namespace pneumo::serve {

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

/// The page's pressures: up to 40 mmHg, well past the 12–15 of practice and the 30 of McDougall's
/// curve; a slider cannot reach beyond, and the API refuses it.
constexpr double kMaxPressureMmHg = 40.0;

}  // namespace

PlanningSession::PlanningSession(nlohmann::json scene_json, std::string scene_path, GlBackend backend)
    : scene_json_(std::move(scene_json)),
      scene_path_(std::move(scene_path)),
      scene_(parse_scene(scene_json_, scene_path_)),
      renderer_(false, backend) {
  sim_ = prepare_simulation(scene_);
  x_ = sim_.mesh.rest_m;
  case_ = {{"ports", scene_ports()}, {"labels", label_list()}};
  {
    std::lock_guard<std::mutex> lock(status_mutex_);
    status_ = nlohmann::json{{"pressure_mmhg", 0.0},
             {"target_pressure_mmhg", scene_.load.pressure_mmhg},
             {"wall_young_kpa", scene_.material.wall_young_kpa.value_or(scene_.material.young_kpa)},
             {"preset", scene_json_.value("preset", std::string("none"))},
             {"solving", false},
             {"converged", false},
             {"step", 0},
             {"shape", 0},
             {"tetrahedra", int64_t(sim_.mesh.tets.size())},
             {"renderer", renderer_.describe()}};
  }
  refresh_shape(sim_, scene_, x_, 0.0);
}

InflateRequest PlanningSession::merged(const InflateRequest& r) const {
  std::lock_guard<std::mutex> lock(status_mutex_);
  InflateRequest m = settings_;
  if (r.pressure_mmhg) m.pressure_mmhg = r.pressure_mmhg;
  if (r.wall_young_kpa) m.wall_young_kpa = r.wall_young_kpa;
  if (r.preset) m.preset = r.preset;
  return m;
}

nlohmann::json PlanningSession::scene_ports() const {
  nlohmann::json list = nlohmann::json::array();
  for (const Port& p : scene_.render.ports) list.push_back(port_json(p));
  return list;
}

nlohmann::json PlanningSession::label_list() const {
  // The ids the label map holds, named from inputs.label_names when the scene gives it.
  const std::map<int, std::string> names = scene_label_names(scene_);
  std::vector<uint8_t> present(65536, 0);
  for (uint16_t l : sim_.roles.label) present[l] = 1;
  nlohmann::json list = nlohmann::json::array();
  for (int id = 1; id < 65536; ++id) {
    if (!present[std::size_t(id)]) continue;
    const auto n = names.find(id);
    list.push_back({{"id", id}, {"name", n == names.end() ? "" : n->second}});
  }
  return list;
}

Scene PlanningSession::scene_for(const InflateRequest& request) const {
  const InflateRequest r = merged(request);
  nlohmann::json j = scene_json_;
  if (r.pressure_mmhg) {
    if (!(*r.pressure_mmhg >= 0.0 && *r.pressure_mmhg <= kMaxPressureMmHg))
      throw InputError("pressure_mmhg must be 0 to 40");
    j["load"]["pressure_mmhg"] = *r.pressure_mmhg;
  }
  if (r.wall_young_kpa) j["material"]["wall_young_kpa"] = *r.wall_young_kpa;
  if (r.preset) {
    if (*r.preset != "preview" && *r.preset != "balanced" && *r.preset != "accurate")
      throw InputError("preset must be preview, balanced or accurate");
    j["preset"] = *r.preset;
  }
  j["load"].erase("pressure_curve_mmhg");   // one pressure at a time here
  return parse_scene(j, scene_path_);       // the scene's own checks (a stiffness out of range, …)
}

void PlanningSession::inflate(const InflateRequest& request, SerialWorker& worker, uint64_t generation) {
  const InflateRequest settings = merged(request);
  const Scene next = scene_for(settings);
  const auto t0 = Clock::now();
  {
    std::lock_guard<std::mutex> lock(status_mutex_);
    settings_ = settings;
    status_["solving"] = true;
    status_["converged"] = false;
    status_["error"] = nullptr;
    status_["target_pressure_mmhg"] = next.load.pressure_mmhg;
    status_["wall_young_kpa"] = next.material.wall_young_kpa.value_or(next.material.young_kpa);
    if (request.preset) status_["preset"] = *request.preset;
    status_["generation"] = generation;
  }
  // Another lattice (the preset's cube size) is another mesh: roles and mesh again, from rest.
  // Another stiffness is the same mesh with other moduli: rebuilt, and the shape carries over.
  const bool new_mesh = next.mesh.cube_voxels != scene_.mesh.cube_voxels || next.mesh.cube_mm != scene_.mesh.cube_mm;
  if (new_mesh) {
    // Prepared and shown aside, then committed: until then the views use the old case whole.
    Simulation prepared = prepare_simulation(next);
    refresh_shape(prepared, next, prepared.mesh.rest_m, 0.0);
    last_exterior_.reset();   // a pick on it would map through roles that are about to go
    sim_ = std::move(prepared);   // the roles' buffers move with it: the new point map stays valid
    x_ = sim_.mesh.rest_m;
    pressure_pa_ = 0.0;
  } else if (next.echo()["material"] != scene_.echo()["material"]) {
    sim_.mesh = build_scene_mesh(voxel_roles_of(sim_.roles), next, /*to_solve=*/true);
  }
  scene_ = next;
  worker.checkpoint(generation);

  SolveHooks hooks;
  hooks.x_start = x_;
  hooks.start_pressure_pa = pressure_pa_;
  hooks.snapshot_every_steps = 1;
  // The first snapshot's shape is shown at once (the first sign the request took), later ones as
  // often as the refresh's own cost allows.
  auto last_refresh = Clock::now() - std::chrono::hours(1);
  double refresh_cost_s = 0.0;
  hooks.on_snapshot = [&](const SolverSnapshot& s) {
    {
      std::lock_guard<std::mutex> lock(status_mutex_);
      status_["step"] = s.step;
      status_["pressure_mmhg"] = s.pressure_pa / units::kPaPerMmHg;
      status_["seconds"] = seconds_since(t0);
    }
    if (seconds_since(last_refresh) >= std::max(kShapeRefreshSeconds, 2.0 * refresh_cost_s)) {
      const auto r0 = Clock::now();
      refresh_shape(sim_, scene_, s.x, s.pressure_pa);
      last_refresh = Clock::now();
      refresh_cost_s = seconds_since(r0);
      log::debug("serve: shape of step " + std::to_string(s.step) + " shown " + std::to_string(seconds_since(t0)) +
                 " s after the request (warp and upload " + std::to_string(refresh_cost_s) + " s)");
      // The views of the new shape before the next step (a Newton step takes about as long as a view).
      worker.checkpoint_for_views(generation, kViewWait);
      return;
    }
    worker.checkpoint(generation);
  };
  solve_simulation(scene_, sim_, hooks);
  x_ = sim_.result.x;
  pressure_pa_ = sim_.result.final_pressure_pa;
  refresh_shape(sim_, scene_, x_, pressure_pa_);
  const DeformationMetrics d = deformation_metrics(sim_.mesh, x_);
  std::lock_guard<std::mutex> lock(status_mutex_);
  status_["solving"] = false;
  status_["converged"] = sim_.result.converged;
  status_["pressure_mmhg"] = pressure_pa_ / units::kPaPerMmHg;
  status_["anterior_rise_mm"] = d.anterior_rise_mm;
  status_["cavity_volume_ml"] = d.cavity_volume_ml;
  status_["viscera_back_mm"] = d.anterior_viscera_posterior_motion_mm;
  status_["seconds"] = seconds_since(t0);
  status_["steps"] = sim_.result.steps;
  status_["tetrahedra"] = int64_t(sim_.mesh.tets.size());
}

void PlanningSession::refresh_shape(const Simulation& sim, const Scene& scene, const std::vector<Vec3>& x,
                                    double pressure_pa) {
  // Everything is built aside and committed at the end, so a failure (memory, the device) leaves
  // the shape shown before intact, its point map and volume agreeing.
  const auto t0 = Clock::now();
  auto warp_mesh = std::make_shared<const WarpMesh>(make_warp_mesh(sim.mesh, displacements(sim.mesh, x)));
  auto point_map = std::make_shared<const PointMap>(*warp_mesh, sim.roles.role.data());
  WarpSource src;
  src.ct_hu = sim.roles.ct.data<float>();
  src.labels = sim.roles.label.data();
  src.roles = sim.roles.role.data();
  WarpOptions wo;
  wo.cavity_label = uint16_t(scene.output.cavity_label);
  const Geometry& g = sim.roles.geometry;
  const double s_map = seconds_since(t0);
  const WarpResult& w = warps_.warp(scene.device, *warp_mesh, src, WarpBox{{0, 0, 0}, g.dims}, wo);
  const double s_warp = seconds_since(t0) - s_map;
  // The views' volume straight from the warp; nothing else holds a copy (the slices and the port
  // ranking read this one).
  auto volume = std::make_unique<RenderVolume>(render_volume_of(w, g));
  volume->smoothing_mm = scene.render.smoothing_mm;
  const double s_volume = seconds_since(t0) - s_map - s_warp;
  renderer_.set_volume(*volume);
  log::debug("serve: shape refreshed: point map " + std::to_string(s_map) + " s, warp " + std::to_string(s_warp) +
             " s, volumes " + std::to_string(s_volume) + " s, upload " +
             std::to_string(seconds_since(t0) - s_map - s_warp - s_volume) + " s");
  const int64_t gas = w.gas_voxels;
  warp_mesh_ = std::move(warp_mesh);
  point_map_ = std::move(point_map);
  volume_ = std::move(volume);
  shown_pressure_pa_ = pressure_pa;
  std::lock_guard<std::mutex> lock(status_mutex_);
  status_["shape"] = status_.value("shape", 0) + 1;
  status_["cavity_voxels"] = gas;
}

void PlanningSession::exterior_shown(const std::string& side, int width, int height, const std::string& what) const {
  if (!last_exterior_) throw InputError(what + " no body's view: ask for one first");
  if (last_exterior_->side != side || last_exterior_->camera.width != width || last_exterior_->camera.height != height)
    throw StaleView(what + " a body's view that is no longer the last one drawn (" + side + " " + std::to_string(width) +
                    "x" + std::to_string(height) + "); ask for it again");
}

PointMapFn PlanningSession::to_deformed() const { return deformed_point_fn(*point_map_, false); }

PlanningSession::Aim PlanningSession::aim(const ScopeRequest& q) const {
  if (!(std::abs(q.yaw_deg) <= 180 && std::abs(q.pitch_deg) <= 89)) throw InputError("yaw_deg ±180, pitch_deg ±89");
  const PointMapFn map = to_deformed();
  const Vec3 target = q.port.target_label ? label_centroid_mm(*volume_, *q.port.target_label) : map(*q.port.target_mm);
  Aim a;
  a.skin = map(q.port.skin_point_mm);
  a.axis = target - a.skin;
  if (a.axis.norm() < 1e-6) throw InputError("the target lies on the port's skin point");
  const Vec3 up(0, 0, 1);
  a.axis = Eigen::AngleAxisd(q.yaw_deg * M_PI / 180.0, up) * a.axis;
  const Vec3 right = a.axis.cross(up);
  if (right.norm() > 1e-9) a.axis = Eigen::AngleAxisd(q.pitch_deg * M_PI / 180.0, right.normalized()) * a.axis;
  return a;
}

std::string PlanningSession::scope_png(const ScopeRequest& q) {
  if (!(q.width >= 16 && q.width <= 1920 && q.height >= 16 && q.height <= 1080))
    throw InputError("the view must be 16 to 1920 × 16 to 1080 pixels");
  const Aim a = aim(q);   // the port itself was checked as a scene's (read_port)
  const ScopePose pose = port_pose(q.port.skin_point_mm, a.skin + a.axis, q.port.insertion_mm, to_deformed(),
                                   q.port.optics.up);
  const ViewCamera camera = make_view_camera(pose, q.port.optics, q.width, q.height);
  const RenderImage image = renderer_.render(camera, settings_from_scene(scene_.render, volume_->geometry));
  RgbImage rgb(image.width, image.height);
  rgb.rgb = to_rgb8(image);
  return encode_png(rgb);
}

std::string PlanningSession::exterior_png(const std::string& side, int width, int height,
                                          const std::vector<Vec3>& ports_mm, bool heat) {
  if (!(width >= 16 && width <= 1920 && height >= 16 && height <= 1080))
    throw InputError("the view must be 16 to 1920 × 16 to 1080 pixels");
  const std::optional<ExteriorCamera> found = exterior_camera(volume_->geometry, side, width, height);
  if (!found) throw InputError("side must be anterior or left");
  const ExteriorCamera& c = *found;
  const RenderSettings s = skin_settings(settings_from_scene(scene_.render, volume_->geometry), c.camera,
                                         volume_->geometry);
  const RenderImage image = renderer_.render(c.camera, s);
  const PointMapFn map = to_deformed();
  std::vector<SkinMark> marks;
  for (std::size_t k = 0; k < ports_mm.size(); ++k) marks.push_back({"port " + std::to_string(k + 1), map(ports_mm[k])});
  char caption[160];
  std::snprintf(caption, sizeof caption, "%.1f mmHg", shown_pressure_pa_ / units::kPaPerMmHg);
  last_exterior_ = Exterior{side, c.camera, image.depth_mm, warp_mesh_, point_map_};
  if (heat && last_ranking_) {
    // The candidates where the shape shown has carried them (the ranking may be of an earlier one).
    PortRanking shown = last_ranking_->ranking;
    for (std::size_t k = 0; k < shown.candidates.size(); ++k)
      if (last_ranking_->on_ct[k]) shown.candidates[k].skin_mm = map(*last_ranking_->on_ct[k]);
    std::snprintf(caption, sizeof caption, "%.1f mmHg, ports for %s", shown_pressure_pa_ / units::kPaPerMmHg,
                  last_ranking_->target_name.c_str());
    return encode_png(port_heat_map(image, c.camera, shown, caption, marks));
  }
  return encode_png(annotated_view(image, c.camera, caption, marks).image);
}

nlohmann::json PlanningSession::rank_ports(int target_label, const std::vector<Vec3>& placed_ports_mm, double grid_mm,
                                          int top, const std::optional<RankRegion>& region) {
  if (region) exterior_shown(region->side, region->width, region->height, "the region was painted on");
  PortRankOptions o;
  o.target_label = target_label;
  o.gas_label = uint16_t(scene_.output.cavity_label);
  o.grid_mm = grid_mm;
  const PointMapFn map = to_deformed();
  for (const Vec3& p : placed_ports_mm) o.other_ports_mm.push_back(map(p));
  const Geometry& g = volume_->geometry;
  Ranking r;
  r.ranking = pneumo::rank_ports(volume_->labels.data(), volume_->hu.data(), g, o);
  if (region) {
    // The candidates the user sees inside the region on that view.
    const Exterior& view = *last_exterior_;
    const double xa = std::min(region->x0, region->x1), xb = std::max(region->x0, region->x1);
    const double ya = std::min(region->y0, region->y1), yb = std::max(region->y0, region->y1);
    const auto inside = [&](const PortCandidate& k) {
      const std::optional<Eigen::Vector2d> p = visible_on_view(view.depth_mm, view.camera, k.skin_mm);
      return p && p->x() >= xa && p->x() <= xb && p->y() >= ya && p->y() <= yb;
    };
    auto& all = r.ranking.candidates;
    all.erase(std::remove_if(all.begin(), all.end(), [&](const PortCandidate& k) { return !inside(k); }), all.end());
  }
  r.on_ct = candidates_on_ct(r.ranking, *point_map_, 0.5 * g.spacing_mm.minCoeff());
  nlohmann::json table = port_ranking_json(r.ranking, o, scene_label_names(scene_), r.on_ct, *point_map_);
  r.target_name = table["target"]["name"].get<std::string>();
  last_ranking_ = std::move(r);
  table["pressure_mmhg"] = shown_pressure_pa_ / units::kPaPerMmHg;
  table["candidates_total"] = table["candidates"].size();
  if (region) table["region"] = {{"side", region->side}, {"x0", region->x0}, {"y0", region->y0}, {"x1", region->x1},
                                 {"y1", region->y1}};
  if (int(table["candidates"].size()) > top) table["candidates"].erase(table["candidates"].begin() + top, table["candidates"].end());
  return table;
}

std::optional<Vec3> PlanningSession::pick(const std::string& side, int width, int height, double x_px, double y_px) {
  exterior_shown(side, width, height, "the click was on");
  const ViewCamera& c = last_exterior_->camera;
  if (!(x_px >= 0 && y_px >= 0 && x_px < c.width && y_px < c.height)) return std::nullopt;
  const float depth = last_exterior_->depth_mm[std::size_t(int(y_px) * c.width + int(x_px))];
  const std::optional<Vec3> ray = c.ray(x_px + 0.5, y_px + 0.5);
  if (!(depth > 0.0f) || !ray) return std::nullopt;
  // The deformed skin point, carried back to the CT as given: a port is planned there and travels.
  // A ray that met no surface has no depth (0 or infinite).
  if (!std::isfinite(depth)) return std::nullopt;
  return skin_point_on_ct(*last_exterior_->point_map, c.position_mm + double(depth) * *ray, *ray,
                          0.5 * volume_->geometry.spacing_mm.minCoeff());
}

std::string PlanningSession::slices_png() {
  SliceView view;
  view.title = "before";
  const RgbImage before = render_slice_row(sim_.roles.ct, nullptr, view);
  char title[96];
  std::snprintf(title, sizeof title, "after, %.1f mmHg", shown_pressure_pa_ / units::kPaPerMmHg);
  view.title = title;
  Volume after(volume_->geometry, VoxelType::Float32);
  std::copy(volume_->hu.begin(), volume_->hu.end(), after.data<float>());
  return encode_png(stack_rows({before, render_slice_row(after, nullptr, view)}));
}

nlohmann::json PlanningSession::plan_json(const std::vector<ScopeRequest>& ports) const {
  nlohmann::json j = scene_json_;
  j["load"]["pressure_mmhg"] = scene_.load.pressure_mmhg;
  j["load"].erase("pressure_curve_mmhg");   // the page solves one pressure; so does its plan
  if (scene_.material.wall_young_kpa) j["material"]["wall_young_kpa"] = *scene_.material.wall_young_kpa;
  {
    std::lock_guard<std::mutex> lock(status_mutex_);
    if (settings_.preset) j["preset"] = *settings_.preset;
  }
  nlohmann::json list = nlohmann::json::array();
  for (const ScopeRequest& q : ports) {
    Port p = q.port;
    if (q.yaw_deg != 0.0 || q.pitch_deg != 0.0) {
      // The dragged axis as a target point on the CT as given: the first point along it, from the
      // target's distance on, that a tetrahedron carries (the gas in front of tissue is carried by
      // none). It travels with that tissue, as a scene's target_mm does.
      const Aim a = aim(q);
      const double step = 0.5 * volume_->geometry.spacing_mm.minCoeff(), length = a.axis.norm();
      std::optional<Vec3> on_ct;
      for (double t = length; t <= 3.0 * length && !on_ct; t += step) {
        const MappedPoint back = point_map_->to_original(a.skin + t / length * a.axis);
        if (back.carried) on_ct = back.point_mm;
      }
      if (!on_ct) throw InputError(p.name + ": the dragged aim leaves the body without meeting tissue; aim again");
      p.target_mm = on_ct;
      p.target_label.reset();
    }
    list.push_back(port_json(p));
  }
  j["render"]["ports"] = list;
  return j;
}

nlohmann::json PlanningSession::status() const {
  std::lock_guard<std::mutex> lock(status_mutex_);
  return status_;
}

void PlanningSession::set_error(const std::string& message) {
  std::lock_guard<std::mutex> lock(status_mutex_);
  status_["solving"] = false;
  status_["error"] = message;
}

}  // namespace pneumo::serve
