#include "pipeline/view_resolution_study.h"

#include <chrono>
#include <cstring>
#include <filesystem>
#include <limits>

#include "core/error.h"
#include "core/stopwatch.h"
#include "core/log.h"
#include "io/volume.h"
#include "io/volume_io.h"
#include "core/atomic_file.h"
#include "render/transfer_function.h"
#include "pipeline/exterior_views.h"
#include "pipeline/render_scene.h"
#include "pipeline/scene_stages.h"
#include "pipeline/simulate.h"
#include "render/image_out.h"
#include "render/poses.h"
#include "render/renderer.h"
#include "warp/cavity_specks.h"
#include "warp/point_map.h"
#include "warp/warp.h"

namespace fs = std::filesystem;

namespace pneumo {
namespace {

constexpr int kStomachLabel = 6;   // TotalSegmentator v2 "stomach", as the phantom's labels

/// The phantom's scene for `size`, its inputs read from memory (paths are never opened here).
Scene phantom_scene(PhantomSize size, const fs::path& dir) {
  return parse_scene(nlohmann::json::parse(phantom_scene_json(size)), (dir / "scene.json").string());
}

/// The slices of `ph` whose centres lie within `box`'s z range (half a slice of slack): the small
/// phantom is 84 mm taller than the others, and a body cut at other heights is another picture.
Phantom cropped_in_z(Phantom ph, const Geometry& box) {
  const Geometry& g = ph.ct.geometry();
  const double lo = box.origin_mm.z() - 0.5 * g.spacing_mm.z();
  const double hi = box.origin_mm.z() + (double(box.dims[2]) - 1.0) * box.spacing_mm.z() + 0.5 * g.spacing_mm.z();
  int64_t k0 = 0, k1 = g.dims[2];
  while (k0 < k1 && g.origin_mm.z() + double(k0) * g.spacing_mm.z() < lo) ++k0;
  while (k1 > k0 && g.origin_mm.z() + double(k1 - 1) * g.spacing_mm.z() > hi) --k1;
  if (k0 == 0 && k1 == g.dims[2]) return ph;
  Geometry c = g;
  c.dims[2] = k1 - k0;
  c.origin_mm = g.to_world(Vec3(0, 0, double(k0)));
  auto crop = [&](const Volume& v) {
    Volume out(c, v.type());
    const std::size_t slice = v.byte_count() / std::size_t(g.dims[2]);
    std::memcpy(out.raw(), static_cast<const uint8_t*>(v.raw()) + slice * std::size_t(k0), slice * std::size_t(k1 - k0));
    return out;
  };
  return Phantom{crop(ph.ct), crop(ph.labels)};
}

/// A scope in the stomach's gas: the gas voxel (stomach label, below −500 HU) nearest the gas's
/// centroid, looking at the centroid of the stomach's tissue (its wall and contents).
ViewCamera stomach_camera(const Phantom& ph, int width, int height) {
  const Geometry& g = ph.ct.geometry();
  const int16_t* hu = ph.ct.data<int16_t>();
  const uint8_t* label = ph.labels.data<uint8_t>();
  auto world = [&](int64_t v) {
    const int64_t nx = g.dims[0], ny = g.dims[1];
    return g.to_world(Vec3(double(v % nx), double((v / nx) % ny), double(v / (nx * ny))));
  };
  Vec3 gas_sum = Vec3::Zero(), tissue_sum = Vec3::Zero();
  int64_t gas_n = 0, tissue_n = 0;
  for (int64_t v = 0; v < g.voxel_count(); ++v) {
    if (label[v] != kStomachLabel) continue;
    if (hu[v] < -500) { gas_sum += world(v); ++gas_n; }
    else { tissue_sum += world(v); ++tissue_n; }
  }
  if (gas_n == 0 || tissue_n == 0) throw InputError("validate view-resolution: the phantom's stomach holds no gas");
  const Vec3 gas_c = gas_sum / double(gas_n);
  Vec3 tip = gas_c;
  double best = std::numeric_limits<double>::infinity();
  for (int64_t v = 0; v < g.voxel_count(); ++v) {
    if (label[v] != kStomachLabel || hu[v] >= -500) continue;
    const double d2 = (world(v) - gas_c).squaredNorm();
    if (d2 < best) { best = d2; tip = world(v); }
  }
  Optics optics;
  return make_view_camera(look_at_pose(tip, tissue_sum / double(tissue_n), optics.up), optics, width, height);
}

struct Shading {
  const char* name;
  double smoothing_mm;
};
constexpr Shading kShadings[] = {{"voxel", 0.0}, {"smooth", kDefaultSmoothingMm}};

}  // namespace

ViewResolutionStudy view_resolution_study(const ViewResolutionOptions& o) {
  if (o.sizes.size() < 2) throw InputError("validate view-resolution: give at least 2 sizes");
  if (!o.force && fs::exists(fs::path(o.out_dir) / "study.json"))
    throw InputError(o.out_dir + ": already holds a view-resolution study (study.json); use --force to replace it");
  const auto start = std::chrono::steady_clock::now();
  ViewResolutionStudy s;
  const fs::path out(o.out_dir);
  fs::create_directories(out / "views");

  // One deformation for all: the coarsest case solved as its scene says.
  const PhantomSize coarse = o.sizes.front();
  const fs::path solve_dir = out / ("solve_" + std::string(phantom_size_name(coarse)));
  write_phantom_case(make_phantom(coarse), coarse, solve_dir.string());
  const Scene solve_scene = load_scene((solve_dir / "scene.json").string());
  log::info("view-resolution: solving the " + std::string(phantom_size_name(coarse)) + " phantom once");
  auto t0 = std::chrono::steady_clock::now();
  Simulation sim = simulate_scene(solve_scene);
  s.solve_seconds = seconds_since(t0);
  std::vector<Vec3> disp(sim.result.x.size());
  for (std::size_t n = 0; n < disp.size(); ++n) disp[n] = sim.result.x[n] - sim.mesh.rest_m[n];
  const WarpMesh solved = make_warp_mesh(sim.mesh, disp);
  const Port port = solve_scene.render.ports.at(0);

  Renderer renderer(o.cpu_reference, o.backend);
  struct View { std::string name; ViewCamera camera; };
  std::vector<View> views;   // fixed by the finest size, the first one rendered
  // Reference images per view and shading.
  std::vector<RenderImage> reference;
  nlohmann::json peer_sizes = nlohmann::json::array(), peer_views = nlohmann::json::array();
  if (o.write_volumes) fs::create_directories(out / "volumes");
  // Finest first: it fixes the cameras and is what the others are compared with.
  for (auto it = o.sizes.rbegin(); it != o.sizes.rend(); ++it) {
    const PhantomSize size = *it;
    const std::string size_name = phantom_size_name(size);
    log::info("view-resolution: the " + size_name + " phantom");
    const Phantom ph = cropped_in_z(make_phantom(size), phantom_geometry(o.sizes.back()));
    const Geometry& g = ph.ct.geometry();
    const Scene scene = phantom_scene(size, out / size_name);
    const RoleVolume roles = assign_roles(scene, ph.ct, &ph.labels);
    const WarpMesh wm = warp_mesh_on_grid(solved, roles.geometry);
    const WarpSource src{roles.ct.data<float>(), roles.label.data(), roles.role.data()};
    WarpBox box;
    box.lo = roles.pad.lo;
    box.dims = g.dims;
    WarpOptions wo;
    wo.cavity_label = uint16_t(scene.output.cavity_label);
    WarpResult warped = warp_on_device("cpu", wm, src, box, wo);
    const double voxel_ml = g.spacing_mm.prod() / 1000.0;
    fill_cavity_specks(warped, box.dims, int64_t(std::ceil(scene.output.min_cavity_piece_ml / voxel_ml)));
    RenderVolume deformed = render_volume_of(warped, g);
    warped = WarpResult{};
    RenderVolume undeformed = RenderVolume::from(ph.ct, &ph.labels);

    if (views.empty()) {
      views.push_back({"stomach_gas", stomach_camera(ph, o.width, o.height)});
      views.push_back({"exterior_anterior", exterior_camera(g, "anterior", o.width, o.height)->camera});
      const PointMap map(wm, roles.role.data());
      const Vec3 target = label_centroid_mm(deformed, *port.target_label);
      const ScopePose pose = port_pose(port.skin_point_mm, target, port.insertion_mm, deformed_point_fn(map), port.optics.up);
      views.push_back({port.name + "_inflated", make_view_camera(pose, port.optics, o.width, o.height)});
    }
    const RenderSettings base = settings_from_scene(scene.render, g);
    if (o.write_volumes) {
      Volume d(g, VoxelType::Int16);
      int16_t* dv = d.data<int16_t>();
      for (std::size_t n = 0; n < deformed.hu.size(); ++n) dv[n] = int16_t(deformed.hu[n]);
      write_metaimage(ph.ct, (out / "volumes" / (size_name + "_ct.mhd")).string(), false);
      write_metaimage(d, (out / "volumes" / (size_name + "_deformed_ct.mhd")).string(), false);
      // The phantom's grid is axis-aligned (direction identity): origin and spacing place it in RAS mm,
      // the cameras' frame, without the MetaImage header's LPS.
      peer_sizes.push_back({{"size", size_name}, {"spacing_mm", g.spacing_mm.maxCoeff()}, {"step_mm", base.step_mm},
                            {"origin_ras_mm", {g.origin_mm.x(), g.origin_mm.y(), g.origin_mm.z()}},
                            {"dims", {g.dims[0], g.dims[1], g.dims[2]}},
                            {"ct", "volumes/" + size_name + "_ct.mhd"},
                            {"deformed_ct", "volumes/" + size_name + "_deformed_ct.mhd"}});
      if (peer_views.empty())
        for (const View& v : views) {
          const bool exterior = v.name.rfind("exterior", 0) == 0;
          const RenderSettings rs = exterior ? skin_settings(base, v.camera, g) : base;
          auto vec = [](const Vec3& x) { return nlohmann::json::array({x.x(), x.y(), x.z()}); };
          peer_views.push_back({{"name", v.name}, {"volume", v.name.find("_inflated") != std::string::npos ? "deformed_ct" : "ct"},
                                {"position_mm", vec(v.camera.position_mm)},
                                {"focal_mm", vec(v.camera.position_mm + 100.0 * v.camera.forward)},
                                {"up", vec(v.camera.up)}, {"fov_deg", v.camera.fov_deg}, {"near_mm", v.camera.near_mm},
                                {"width", v.camera.width}, {"height", v.camera.height},
                                {"opacity", rs.tf.opacity}, {"colour", rs.tf.colour}, {"ambient", rs.ambient},
                                {"diffuse", rs.diffuse}, {"specular", rs.specular}, {"shininess", rs.shininess}});
        }
    }
    std::size_t ref_index = 0;
    for (const Shading& sh : kShadings) {
      deformed.smoothing_mm = undeformed.smoothing_mm = sh.smoothing_mm;
      for (const View& v : views) {
        const bool exterior = v.name.rfind("exterior", 0) == 0, inflated = v.name.find("_inflated") != std::string::npos;
        renderer.set_volume(inflated ? deformed : undeformed);
        const RenderSettings rs = exterior ? skin_settings(base, v.camera, g) : base;
        const auto f0 = std::chrono::steady_clock::now();
        const RenderImage im = renderer.render(v.camera, rs);
        ViewResolutionRow row;
        row.frame_seconds = seconds_since(f0);
        row.view = v.name;
        row.size = size_name;
        row.shading = sh.name;
        row.spacing_mm = g.spacing_mm.maxCoeff();
        const std::string file = "views/" + v.name + "_" + size_name + "_" + sh.name + ".png";
        write_view_png((out / file).string(), im);
        s.images.push_back(file);
        if (reference.size() <= ref_index) reference.push_back(im);
        row.ssim = ssim(im, reference[ref_index]);
        row.psnr_db = psnr_db(im, reference[ref_index]);
        ++ref_index;
        s.rows.push_back(row);
      }
    }
  }
  if (o.write_volumes)
    write_text_file_atomic((out / "peer_views.json").string(),
                           nlohmann::json{{"sizes", peer_sizes}, {"views", peer_views}}.dump(2) + "\n");
  s.seconds = seconds_since(start);
  return s;
}

nlohmann::json to_json(const ViewResolutionStudy& s) {
  nlohmann::json rows = nlohmann::json::array();
  for (const ViewResolutionRow& r : s.rows)
    rows.push_back({{"view", r.view}, {"size", r.size}, {"shading", r.shading}, {"spacing_mm", r.spacing_mm},
                    {"ssim", r.ssim}, {"psnr_db", std::isfinite(r.psnr_db) ? nlohmann::json(r.psnr_db) : nlohmann::json()},
                    {"frame_seconds", r.frame_seconds}});
  return {{"rows", rows}, {"images", s.images}, {"solve_seconds", s.solve_seconds}, {"seconds", s.seconds}};
}

}  // namespace pneumo
