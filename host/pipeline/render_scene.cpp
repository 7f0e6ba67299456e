#include "pipeline/render_scene.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <optional>
#include <stdexcept>

#include "core/atomic_file.h"
#include "core/child_process.h"
#include "core/error.h"
#include "core/log.h"
#include "core/owned_folder.h"
#include "core/progress.h"
#include "core/thread_count.h"
#include "image/png.h"
#include "io/volume_io.h"
#include "pipeline/exterior_views.h"
#include "pipeline/scene_stages.h"
#include "render/camera_path.h"
#include "render/image_out.h"
#include "render/renderer.h"
#include "roles/label_map.h"

namespace pneumo {
namespace fs = std::filesystem;
namespace {

nlohmann::json vec_json(const Vec3& v) { return nlohmann::json::array({v.x(), v.y(), v.z()}); }

std::string show(const Vec3& v) {
  char b[96];
  std::snprintf(b, sizeof b, "[%.1f, %.1f, %.1f]", v.x(), v.y(), v.z());
  return b;
}

void require_inside(const RenderVolume& v, const Vec3& tip, const std::string& what) {
  if (v.contains(tip)) return;
  const Geometry& g = v.geometry;
  const Vec3 a = g.to_world(Vec3::Zero());
  const Vec3 b = g.to_world(Vec3(double(g.dims[0] - 1), double(g.dims[1] - 1), double(g.dims[2] - 1)));
  throw InputError(what + ": the scope tip " + show(tip) + " mm lies outside the volume (" + show(a.cwiseMin(b)) +
                   " to " + show(a.cwiseMax(b)) + " mm); the laparoscope renders from inside");
}

nlohmann::json pose_json(const ViewCamera& c) {
  return {{"tip_mm", vec_json(c.position_mm)}, {"forward", vec_json(c.forward)}, {"up", vec_json(c.up)},
          {"lens", enum_name(c.lens)},         {"fov_deg", c.fov_deg}};
}

// The fly-through strip: frames at most 320 px wide (box-filtered), JPEG quality 85 — about
// 15 kB a frame, so the report carries a whole path for the bytes of one view's PNG.
int strip_downscale(int width) { return std::max(1, (width + 319) / 320); }
constexpr int kStripJpegQuality = 85;

}  // namespace

RenderVolume render_volume_of(const WarpResult& w, const Geometry& g) {
  RenderVolume v;
  v.geometry = g;
  v.hu.resize(w.ct_hu.size());
  for (std::size_t n = 0; n < w.ct_hu.size(); ++n) v.hu[n] = std::nearbyint(std::clamp(w.ct_hu[n], -32767.0f, 32767.0f));
  v.hu_is_int16 = true;
  v.labels = w.labels;
  return v;
}

RenderSettings settings_from_scene(const ViewSettings& r, const Geometry& g) {
  RenderSettings s;
  s.tf = scene_transfer_function(r);
  s.step_mm = r.step_fraction * g.spacing_mm.minCoeff();  // §8: at most half the smallest spacing
  s.jitter = r.jitter;
  s.show_labels = r.show_labels;
  s.label_opacity = r.label_opacity;
  s.label_colours = preset_label_colours(r.preset);
  s.ambient = r.ambient;
  s.diffuse = r.diffuse;
  s.specular = r.specular;
  s.shininess = r.shininess;
  s.light_falloff_mm = r.light_falloff_mm;
  s.vignetting_power = r.vignetting_power;
  s.antialias_samples = r.antialias_samples;
  return s;
}

void check_port_targets(const Scene& scene, const RoleVolume& roles) {
  std::vector<char> present;   // by id, filled at the first port that aims at a label
  for (const Port& p : scene.render.ports) {
    if (!p.target_label) continue;
    const int id = *p.target_label;
    if (scene.inputs.labels.empty())
      throw InputError("port '" + p.name + "': target_label " + std::to_string(id) + " needs a label map (inputs.labels)");
    if (present.empty()) {
      present.assign(65536, 0);
      for (const uint16_t l : roles.label) present[l] = 1;
    }
    if (id < 0 || id > 65535 || !present[std::size_t(id)])
      throw file_error(scene.inputs.labels, "port '" + p.name + "': target_label " + std::to_string(id) +
                                                " labels no voxel of this label map; aim it at an id the map holds "
                                                "(pneumo info lists them) or at target_mm");
  }
}

bool ffmpeg_available() { return find_program("ffmpeg").has_value(); }

namespace {

/// A path as ffmpeg's file protocol takes it: "file:" first, so that no part of it is read as another
/// protocol ("http:…") or as an option ("-…").
std::string ffmpeg_file(const fs::path& p) { return "file:" + p.string(); }

/// The frames' pattern for ffmpeg's image2 reader, which reads % as a pattern: a % in the folder's
/// name is written %% (a literal %).
std::string frame_pattern(const fs::path& frame_dir) {
  std::string dir;
  for (const char c : frame_dir.string()) dir += c == '%' ? std::string("%%") : std::string(1, c);
  return "file:" + dir + "/frame_%04d.png";
}

}  // namespace

// frames → <dir>.mp4 (H.264); written beside and renamed, so it is atomic too. The input rate is the
// playback rate: every PNG becomes one frame, none dropped or repeated. ffmpeg gets an argument
// vector, never a shell: the folder's name is passed as it is, whatever it holds.
bool encode_mp4(const fs::path& frame_dir, const fs::path& mp4, double fps) {
  const fs::path tmp = mp4.string() + ".part.mp4";
  char rate[32];
  std::snprintf(rate, sizeof rate, "%.6g", fps);
  const int code = run_program({"ffmpeg", "-nostdin", "-y", "-loglevel", "error", "-framerate", rate, "-i",
                                frame_pattern(frame_dir), "-vf", "pad=ceil(iw/2)*2:ceil(ih/2)*2", "-c:v", "libx264",
                                "-pix_fmt", "yuv420p", ffmpeg_file(tmp)});
  if (code != 0) {
    std::error_code ec;
    fs::remove(tmp, ec);
    log::warn("ffmpeg could not encode " + mp4.string() + " (exit " + std::to_string(code) +
              "); the frames are kept as PNGs");
    return false;
  }
  fs::rename(tmp, mp4);
  return true;
}

RenderRun render_scene(const Scene& scene, const RenderOptions& opt) {
  const ViewSettings& r = scene.render;
  RenderRun run;
  const fs::path out(opt.out_dir);
  const fs::path deformed_ct = out / "deformed_ct.nii.gz", deformed_labels = out / "deformed_labels.nii.gz";
  if (fs::exists(deformed_ct)) {
    run.deformed = true;
    run.ct_path = deformed_ct.string();
    if (fs::exists(deformed_labels)) run.labels_path = deformed_labels.string();
    if (!opt.map_point)
      log::warn("rendering the deformed CT without the warp's point mapping: port skin points and target_mm are "
                "used as given");
  } else {
    run.ct_path = scene.require_ct();
    run.labels_path = scene.inputs.labels;
  }
  scene_transfer_function(r);  // a bad custom transfer function is reported before the CT is read

  log::info("render: " + run.ct_path + (run.labels_path.empty() ? "" : " with labels " + run.labels_path));
  const Volume ct = read_volume(run.ct_path);
  std::unique_ptr<Volume> labels;
  if (!run.labels_path.empty()) {
    labels = std::make_unique<Volume>(read_volume(run.labels_path));
    check_labels_on_ct_grid(ct.geometry(), labels->geometry(), run.ct_path, run.labels_path);
    check_label_values(*labels, run.labels_path);
  }
  // The exterior views show the body before inflation beside the deformed one.
  RenderOptions with_before = opt;
  std::optional<Volume> undeformed;
  if (run.deformed && r.exterior_views && !opt.undeformed_ct) {
    undeformed = read_volume(scene.require_ct());
    with_before.undeformed_ct = &*undeformed;
  }
  return render_volumes(scene, with_before, ct, labels.get(), run);
}

namespace {

// The render stage once its threads are fitted to the load: each public overload samples the load
// once, first, so that every pass over the 10⁸ voxels (the float conversion included) runs on the
// cores other processes leave.
RenderRun render_fitted(const Scene& scene, const RenderOptions& opt, const RenderVolume& volume, RenderRun run);

}  // namespace

RenderRun render_volumes(const Scene& scene, const RenderOptions& opt, const Volume& ct, const Volume* labels,
                         RenderRun run) {
  fit_threads_to_load();
  RenderVolume volume = RenderVolume::from(ct, labels);
  volume.smoothing_mm = scene.render.smoothing_mm;
  return render_fitted(scene, opt, volume, std::move(run));
}

RenderRun render_volumes(const Scene& scene, const RenderOptions& opt, const RenderVolume& volume, RenderRun run) {
  fit_threads_to_load();
  return render_fitted(scene, opt, volume, std::move(run));
}

namespace {

RenderRun render_fitted(const Scene& scene, const RenderOptions& opt, const RenderVolume& volume, RenderRun run) {
  const auto start = std::chrono::steady_clock::now();
  const ViewSettings& r = scene.render;
  const fs::path out(opt.out_dir);
  const fs::path deformed_labels = out / "deformed_labels.nii.gz";
  const PointMapFn map = opt.map_point ? opt.map_point : identity_point_map();
  const bool labels = !volume.labels.empty();
  if (volume.smoothing_mm != r.smoothing_mm)
    throw std::logic_error("render_volumes: the volume's smoothing_mm differs from the scene's render.smoothing_mm");
  const RenderSettings s = settings_from_scene(r, volume.geometry);

  // Poses first: every bad one is reported before any rendering.
  struct View { std::string name; ViewCamera camera; };
  std::vector<View> views;
  for (const Camera& c : r.cameras) {
    const ViewCamera cam = make_view_camera(look_at_pose(c.position_mm, c.look_at_mm, c.optics.up), c.optics, r.width,
                                            r.height);
    require_inside(volume, cam.position_mm, "camera '" + c.name + "'");
    views.push_back({c.name, cam});
  }
  for (const Port& p : r.ports) {
    // target_mm is planned on the original CT like the skin point, so it travels with the tissue;
    // a label's centroid is taken where the labels are (deformed when the warp left them).
    Vec3 target;
    if (p.target_mm) {
      target = map(*p.target_mm);
    } else if (run.deformed && labels) {
      target = label_centroid_mm(volume, *p.target_label);
    } else if (run.deformed) {
      throw InputError("port '" + p.name + "': target_label needs the deformed label map " +
                       deformed_labels.string() + ", which is missing");
    } else {
      target = map(label_centroid_mm(volume, *p.target_label));
    }
    const ScopePose pose = port_pose(p.skin_point_mm, target, p.insertion_mm, map, p.optics.up);
    const ViewCamera cam = make_view_camera(pose, p.optics, r.width, r.height);
    require_inside(volume, cam.position_mm, "port '" + p.name + "'");
    views.push_back({p.name, cam});
  }
  struct Path { std::string name; std::vector<ViewCamera> cameras; };
  std::vector<Path> paths;
  for (const CameraPath& p : r.paths) {
    for (std::size_t k = 0; k < p.keyframes.size(); ++k)
      require_inside(volume, p.keyframes[k].position_mm, "path '" + p.name + "' keyframe " + std::to_string(k));
    Path path{p.name, {}};
    for (const ScopePose& pose : interpolate_path(p.keyframes, p.frames, p.optics.up))
      path.cameras.push_back(make_view_camera(pose, p.optics, r.width, r.height));
    paths.push_back(std::move(path));
  }

  const int exterior = r.exterior_views ? 2 : 0;
  int64_t total = int64_t(views.size()) + exterior;
  for (const Path& p : paths) total += int64_t(p.cameras.size());
  if (total == 0) throw InputError("the scene's render section has no cameras, ports, paths or exterior views");

  Renderer renderer(opt.cpu_reference, opt.backend);
  create_owned_folder(out / "views");
  renderer.set_volume(volume);
  nlohmann::json view_report = nlohmann::json::array();
  Progress progress("render", total);
  int64_t done = 0;
  auto tick = [&](const std::string& what) { progress.update(++done, what); };

  for (const View& v : views) {
    const RenderImage im = renderer.render(v.camera, s);
    const std::string rel = "views/" + v.name + ".png";
    write_view_png((out / rel).string(), im);
    run.files.push_back(rel);
    if (scene.output.write_depth) {
      const std::string drel = "views/" + v.name + "_depth.png";
      write_depth_png((out / drel).string(), im);
      run.files.push_back(drel);
    }
    nlohmann::json j = pose_json(v.camera);
    j["name"] = v.name;
    j["file"] = rel;
    view_report.push_back(j);
    ++run.views;
    tick(v.name);
  }

  nlohmann::json path_report = nlohmann::json::array();
  const bool mp4 = !paths.empty() && ffmpeg_available();
  for (const Path& p : paths) {
    const fs::path dir = out / "flythrough" / p.name;
    create_owned_folder(out / "flythrough");
    fs::create_directories(dir);
    std::vector<RgbImage> thumbnails;
    for (std::size_t f = 0; f < p.cameras.size(); ++f) {
      char name[32];
      std::snprintf(name, sizeof name, "frame_%04zu.png", f + 1);
      const RenderImage frame = renderer.render(p.cameras[f], s);
      RgbImage rgb(frame.width, frame.height);
      rgb.rgb = to_rgb8(frame);   // once, for the PNG and the strip's thumbnail
      write_png((dir / name).string(), rgb);
      thumbnails.push_back(box_downscale(rgb, strip_downscale(frame.width)));
      run.files.push_back("flythrough/" + p.name + "/" + name);
      ++run.frames;
      tick(p.name + " " + std::to_string(f + 1) + "/" + std::to_string(p.cameras.size()));
    }
    nlohmann::json j = {{"name", p.name}, {"frames", p.cameras.size()}, {"folder", "flythrough/" + p.name}};
    // The frames side by side, smaller, as one JPEG: the report plays it as an animation.
    const std::string strip = "flythrough/" + p.name + "_strip.jpg";
    write_jpeg((out / strip).string(), hconcat(thumbnails, 0, Rgb{}), kStripJpegQuality);
    run.files.push_back(strip);
    j["strip"] = {{"file", strip}, {"frame_px", {thumbnails.front().width, thumbnails.front().height}}};
    if (mp4 && encode_mp4(dir, out / "flythrough" / (p.name + ".mp4"), r.video_fps)) {
      run.files.push_back("flythrough/" + p.name + ".mp4");
      j["mp4"] = "flythrough/" + p.name + ".mp4";
      j["fps"] = r.video_fps;
    }
    path_report.push_back(j);
  }
  if (!paths.empty() && !mp4) log::info("render: ffmpeg not found; fly-throughs are PNG frames only");

  if (exterior) {
    // The body from outside: the skin, after inflation and (when the CT before it is at hand) before
    // it, side by side under one camera, the ports marked. Last of all views, since the CT before
    // inflation replaces the volume on the renderer.
    const std::vector<ExteriorCamera> cameras = exterior_cameras(volume.geometry, r.width, r.height);
    std::vector<SkinMark> before_marks, after_marks;
    for (const Port& p : r.ports) {
      before_marks.push_back({p.name, p.skin_point_mm});
      after_marks.push_back({p.name, map(p.skin_point_mm)});
    }
    std::vector<RenderImage> after;
    for (const ExteriorCamera& c : cameras) after.push_back(renderer.render(c.camera, skin_settings(s, c.camera, volume.geometry)));
    std::vector<RenderImage> before;
    if (opt.undeformed_ct) {
      RenderVolume undeformed = RenderVolume::from(*opt.undeformed_ct, nullptr);
      undeformed.smoothing_mm = r.smoothing_mm;
      renderer.set_volume(undeformed);
      for (const ExteriorCamera& c : cameras)
        before.push_back(renderer.render(c.camera, skin_settings(s, c.camera, volume.geometry)));
    }
    for (std::size_t k = 0; k < cameras.size(); ++k) {
      const ExteriorCamera& c = cameras[k];
      const AnnotatedView a = annotated_view(after[k], c.camera, run.deformed ? opt.deformed_caption : "CT as given",
                                             run.deformed ? after_marks : before_marks);
      RgbImage picture = a.image;
      nlohmann::json marked = a.marked;
      if (!before.empty()) {
        const AnnotatedView b = annotated_view(before[k], c.camera, "before inflation", before_marks);
        picture = hconcat({b.image, a.image}, 4, Rgb{255, 255, 255});
        marked = {{"before", b.marked}, {"after", a.marked}};
      }
      const std::string rel = "views/" + c.name + ".png";
      write_png_rgb((out / rel).string(), picture.width, picture.height, picture.rgb);
      run.files.push_back(rel);
      nlohmann::json j = pose_json(c.camera);
      j["name"] = c.name;
      j["file"] = rel;
      j["preset"] = "skin";
      j["panels"] = before.empty() ? nlohmann::json::array({"after"}) : nlohmann::json::array({"before", "after"});
      j["ports_marked"] = marked;
      view_report.push_back(j);
      ++run.views;
      tick(c.name);
    }
  }
  progress.finish(std::to_string(run.views) + " views, " + std::to_string(run.frames) + " frames");

  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  run.report = {{"ct", run.ct_path},
                {"labels", run.labels_path},
                {"deformed", run.deformed},
                {"point_mapping", opt.map_point ? "warp" : "identity"},
                {"transfer_function", s.tf.name},
                {"step_mm", s.step_mm},
                {"image", {r.width, r.height}},
                {"render", renderer.describe()},
                {"views", view_report},
                {"paths", path_report},
                {"files", run.files},
                {"seconds", seconds},
                {"scene", scene.echo()}};
  write_text_file_atomic((out / "render.json").string(), run.report.dump(2) + "\n");
  return run;
}

}  // namespace

}  // namespace pneumo
