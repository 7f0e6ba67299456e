#pragma once
// What `pneumo serve` keeps resident for one case: the scene, its roles and mesh, the
// current equilibrium, the CT warped through it and the renderer holding that volume. A pressure or
// stiffness change continues from the last equilibrium (a warm start: the solver starts at its shape
// and pressure), and while it converges the warped volume is refreshed every kShapeRefreshSeconds,
// so the views show the abdomen moving. Every method runs on the SerialWorker's thread (the GL
// context and the solver state live there); status() alone may be called from any thread.
#include <chrono>
#include <cstdint>
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/geometry.h"
#include "pipeline/simulate.h"
#include "plan/port_ranking.h"
#include "render/gl_context.h"
#include "render/renderer.h"
#include "scene/scene.h"
#include "serve/serial_worker.h"
#include "warp/point_map.h"
#include "warp/warp.h"

namespace pneumo::serve {

/// A pick on a body view that is no longer the last one drawn (the server answers 409).
struct StaleView : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// What the page may change; everything else comes from the scene file. Absent = as the last
/// request left it (at first, the scene file's).
struct InflateRequest {
  std::optional<double> pressure_mmhg;    // 0 … 40
  std::optional<double> wall_young_kpa;   // within the scene's limits
  std::optional<std::string> preset;      // "preview", "balanced", "accurate"
};

/// A laparoscope at a port: the scene's own Port (its skin point on the CT as given, which travels
/// with the skin; its target, an organ label's centroid or a point on the CT as given; insertion and
/// optics), read with a scene port's checks (read_port), and the aim the user dragged: yaw and pitch
/// turn the axis from the target about the skin point (degrees).
struct ScopeRequest {
  Port port;
  double yaw_deg = 0.0, pitch_deg = 0.0;   // ±180, ±89
  int width = 480, height = 360;
};

/// A region painted on the last exterior view (pixels, corners in any order): the port ranking keeps
/// only the candidates seen inside it.
struct RankRegion {
  std::string side;
  int width = 0, height = 0;
  double x0 = 0, y0 = 0, x1 = 0, y1 = 0;
};

class PlanningSession {
 public:
  /// The views follow the solve at most this often, and spend at most a third of the time on it
  /// (a refresh warps the CT and uploads the volume: about a second on the medium phantom here).
  static constexpr double kShapeRefreshSeconds = 0.7;
  /// After a new shape, how long the solve waits for the views a watching page asks for it: the
  /// page polls every 0.1 s while a solve runs (page/app.js), so its request comes within this.
  static constexpr std::chrono::milliseconds kViewWait{250};

  /// `scene_json` is the scene file as written (presets apply to it when changed), `scene_path` its
  /// path (relative paths resolve from its folder).
  PlanningSession(nlohmann::json scene_json, std::string scene_path, GlBackend backend);

  /// The scene a request asks for (its values over the settings of the last request, over the
  /// scene file's), checked as any scene is (InputError naming what is wrong), without touching the
  /// case: what the server calls before it answers. Any thread.
  Scene scene_for(const InflateRequest& r) const;

  /// Solves at the request's settings from the last equilibrium (from rest when the preset changes
  /// the mesh), checking `worker` at every solver snapshot: views asked for meanwhile are answered,
  /// and a newer request stops this one (SerialWorker::Superseded).
  void inflate(const InflateRequest& request, SerialWorker& worker, uint64_t generation);

  /// The laparoscope's view on the current shape, as PNG bytes. InputError for a pose that leaves
  /// the volume or an unknown label.
  std::string scope_png(const ScopeRequest& request);
  /// The skin from outside ("anterior" or "left"), after inflation, the given ports marked; the
  /// camera is kept for pick().
  /// With `heat`, the last port ranking's candidates drawn on it in the colours of their scores
  /// (pipeline/port_planning.h), each where the shape shown has carried its skin point.
  std::string exterior_png(const std::string& side, int width, int height, const std::vector<Vec3>& ports_mm,
                           bool heat = false);
  /// The skin point under pixel (x, y) of the last exterior view, which must be the one from `side`
  /// at width × height (StaleView otherwise: the user clicked on another), on the CT as given
  /// (carried back through the shape that view showed); nullopt where the ray met no skin.
  std::optional<Vec3> pick(const std::string& side, int width, int height, double x_px, double y_px);
  /// Axial, coronal and sagittal slices before and after, through the middle of the grid.
  std::string slices_png();

  /// Candidate ports for `target_label` ranked on the shape shown (plan/port_ranking.h), the ports
  /// already placed given on the CT as given: the table `pneumo ports` writes, its first `top`
  /// candidates (candidates_total says how many there were). With `region`, only the candidates
  /// that show inside it on the last exterior view (StaleView when that view is another), scored as
  /// among all. Kept for exterior_png's heat map.
  nlohmann::json rank_ports(int target_label, const std::vector<Vec3>& placed_ports_mm, double grid_mm, int top,
                            const std::optional<RankRegion>& region = std::nullopt);

  /// The scene as it now stands (the file's text with the changes made), to save as a plan, with
  /// `ports` as its render.ports. A port whose aim was dragged aims at a point on the dragged axis
  /// instead of its target (the scene's ports aim at a target); InputError when that axis leaves
  /// the body without meeting tissue the shape carries.
  nlohmann::json plan_json(const std::vector<ScopeRequest>& ports) const;

  /// Thread-safe: the settings, the solve's progress and the last equilibrium's figures.
  nlohmann::json status() const;
  /// Any thread: what does not change while serving, read once by the page: the scene's ports (to
  /// start from) and the label map's ids with their names (the targets).
  const nlohmann::json& case_info() const { return case_; }
  void set_error(const std::string& message);

 private:
  /// Warps sim's CT through shape x and uploads it: the views' volume and point map from then on.
  void refresh_shape(const Simulation& sim, const Scene& scene, const std::vector<Vec3>& x, double pressure_pa);
  InflateRequest merged(const InflateRequest& r) const;                 // r over settings_
  nlohmann::json scene_ports() const;   // the scene's ports, for the page to start from
  nlohmann::json label_list() const;    // the label map's ids with their names, for the targets
  PointMapFn to_deformed() const;
  /// Throws unless the last exterior view drawn is the one from `side` at width × height: InputError
  /// when there is none, StaleView (409) when it is another. `what` begins the message.
  void exterior_shown(const std::string& side, int width, int height, const std::string& what) const;
  /// The scope's axis in the deformed frame: from the port's skin point to its target, turned by
  /// the dragged yaw (about the superior axis) and pitch (about the axis's right). InputError for an
  /// unknown label or a target on the skin point.
  struct Aim {
    Vec3 skin = Vec3::Zero(), axis = Vec3::Zero();   // axis: skin → the (turned) target, full length
  };
  Aim aim(const ScopeRequest& q) const;

  nlohmann::json scene_json_;
  std::string scene_path_;
  nlohmann::json case_;             // set in the constructor, never changed (case_info)
  Scene scene_;
  Simulation sim_;
  std::vector<Vec3> x_;             // the current shape (m), sim_.mesh.rest_m before the first solve
  double pressure_pa_ = 0.0;        // the pressure x_ is in equilibrium with (0: rest)
  double shown_pressure_pa_ = 0.0;  // the pressure of the shape the views show (mid-solve: the solver's)
  std::shared_ptr<const WarpMesh> warp_mesh_;
  std::shared_ptr<const PointMap> point_map_;   // refers to *warp_mesh_ and sim_.roles
  WarpSeries warps_;
  std::unique_ptr<RenderVolume> volume_;   // the shape shown: the deformed CT (whole HU) and labels
  struct Ranking {   // the last port ranking, its candidates' skin points on the CT as given
    PortRanking ranking;
    std::vector<std::optional<Vec3>> on_ct;
    std::string target_name;
  };
  std::optional<Ranking> last_ranking_;
  Renderer renderer_;
  struct Exterior {   // the last exterior view: a pick is made on what the user saw
    std::string side;
    ViewCamera camera;
    std::vector<float> depth_mm;
    std::shared_ptr<const WarpMesh> warp_mesh;    // the shape it showed, kept while picked on
    std::shared_ptr<const PointMap> point_map;
  };
  std::optional<Exterior> last_exterior_;

  mutable std::mutex status_mutex_;   // guards status_ and settings_
  nlohmann::json status_;
  InflateRequest settings_;           // the last request's values, merged (absent: the scene file's)
};

}  // namespace pneumo::serve
