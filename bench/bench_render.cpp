// Renderer benchmarks: frames per second of the laparoscope's view from inside the gas cavity of
// the large phantom (512×512×400 at 0.75 mm), GL (llvmpipe here, or a GPU) at 512² and 1920×1080,
// and the CPU reference (one frame each). Medians over repetitions; never a pass/fail on time. The
// "setup_s" counter is the GL ray caster's one-off set-up (shader compile, gradient computation,
// texture upload), which the per-frame times exclude, as VTK's script separates its own.
//
// The phantom is pneumo's own, before insufflation: it has no cavity. Until the warp's deformed CT
// can be generated here, a gas lens is carved under the anterior wall (45 mm deep at its centre,
// 220 mm across, everything between the wall and the lens's floor set to −1000 HU), like the VTK
// peer's phantom (../shared/peers/phantom.py). With PNEUMO_BENCH_VTK_DIR set, that volume and the
// camera are also written there as phantom.mhd/.raw/.json for ../shared/peers/vtk_render.py, so
// VTK renders the same view at the same size and sample distance.
//   build/bench/pneumo_bench --benchmark_filter=Render --benchmark_repetitions=5
//       --benchmark_report_aggregates_only=true
#include <benchmark/benchmark.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <memory>

#include "core/progress.h"
#include "phantom/phantom.h"
#include "render/image_out.h"
#include "render/renderer.h"
#include "render/ray_cast_ref.h"
#include "scene/scene.h"

using namespace pneumo;

namespace {

struct Bench {
  RenderVolume volume;
  ViewCamera camera;  // 512², 70° pinhole; resized per benchmark
  Vec3 look_at;
};

bool is_wall(uint8_t id) { return id == 0 || id == 200 || id == 201 || id == 202; }  // air, skin, fat, muscle

void export_for_vtk(const Bench& b, const std::string& dir) {
  const Geometry& g = b.volume.geometry;
  std::vector<int16_t> raw(b.volume.hu.size());
  for (std::size_t n = 0; n < raw.size(); ++n) raw[n] = int16_t(b.volume.hu[n]);
  std::ofstream(dir + "/phantom.raw", std::ios::binary).write(reinterpret_cast<const char*>(raw.data()),
                                                               std::streamsize(raw.size() * 2));
  // vtk_render.py reads Offset/ElementSpacing only: its world is this grid's RAS world (direction
  // identity), so the camera numbers are the same.
  std::ofstream(dir + "/phantom.mhd") << "ObjectType = Image\nNDims = 3\nDimSize = " << g.dims[0] << " " << g.dims[1]
                                      << " " << g.dims[2] << "\nElementSpacing = " << g.spacing_mm.x() << " "
                                      << g.spacing_mm.y() << " " << g.spacing_mm.z() << "\nOffset = "
                                      << g.origin_mm.x() << " " << g.origin_mm.y() << " " << g.origin_mm.z()
                                      << "\nElementType = MET_SHORT\nElementDataFile = phantom.raw\n";
  const Vec3& p = b.camera.position_mm;
  std::ofstream(dir + "/phantom.json") << "{\"camera_position\": [" << p.x() << ", " << p.y() << ", " << p.z()
                                       << "], \"camera_focal\": [" << b.look_at.x() << ", " << b.look_at.y() << ", "
                                       << b.look_at.z() << "], \"camera_view_up\": [0, 0, 1]}\n";
}

const Bench& bench() {
  static std::unique_ptr<Bench> b;
  if (b) return *b;
  b = std::make_unique<Bench>();
  Progress::set_enabled(false);
  const Phantom ph = make_phantom(PhantomSize::Large);
  b->volume = RenderVolume::from(ph.ct, &ph.labels);
  // As the render stage reconstructs it (render.smoothing_mm's default); PNEUMO_BENCH_SMOOTHING_MM=0
  // times the voxels as they are.
  const char* smoothing = std::getenv("PNEUMO_BENCH_SMOOTHING_MM");
  b->volume.smoothing_mm = smoothing ? std::atof(smoothing) : kDefaultSmoothingMm;
  RenderVolume& v = b->volume;
  const Geometry& g = v.geometry;
  const uint8_t* lab = ph.labels.data<uint8_t>();
  double y_wall_centre = 0;
  for (int64_t k = 0; k < g.dims[2]; ++k)
    for (int64_t i = 0; i < g.dims[0]; ++i) {
      const Vec3 w = g.to_world(Vec3(double(i), 0, double(k)));
      const double q = 1.0 - (w.x() / 110.0) * (w.x() / 110.0) - (w.z() / 110.0) * (w.z() / 110.0);
      if (q <= 0) continue;
      int64_t j = g.dims[1] - 1;  // j grows anteriorly: walk in from the front through the wall
      while (j > 0 && is_wall(lab[g.linear_index(i, j, k)])) --j;
      const int64_t floor_j = j - int64_t(std::lround(45.0 * std::sqrt(q) / g.spacing_mm.y()));
      for (int64_t jj = std::max<int64_t>(floor_j, 0); jj <= j; ++jj) {
        v.hu[g.linear_index(i, jj, k)] = -1000.0f;
        v.labels[g.linear_index(i, jj, k)] = 0;
      }
      if (i == g.dims[0] / 2 && k == g.dims[2] / 2) y_wall_centre = g.to_world(Vec3(0, double(j), 0)).y();
    }
  // Tip 15 mm under the wall at the centre, looking posterior and superior (the upper abdomen).
  const Vec3 tip(0, y_wall_centre - 15, -40);
  b->look_at = Vec3(0, y_wall_centre - 80, 40);
  Optics o;
  b->camera = make_view_camera(look_at_pose(tip, b->look_at, o.up), o, 512, 512);
  if (const char* dir = std::getenv("PNEUMO_BENCH_VTK_DIR")) export_for_vtk(*b, dir);
  return *b;
}

// The VTK peer's transfer function and Phong coefficients (vtk_render.py build_property), for the
// like-for-like comparison; VTK's light has no distance falloff, so neither has this one.
RenderSettings vtk_like_settings(double step_mm) {
  RenderSettings s;
  s.tf.name = "vtk-peer";
  s.tf.colour = {{-1024, 0, 0, 0},       {-400, 0.3, 0.25, 0.2},  {-90, 0.88, 0.78, 0.45}, {0, 0.8, 0.5, 0.4},
                 {40, 0.82, 0.35, 0.32}, {60, 0.7, 0.22, 0.2},    {200, 0.95, 0.85, 0.75}, {700, 1, 1, 0.95}};
  s.tf.opacity = {{-1024, 0}, {-300, 0}, {-130, 0}, {-90, 0.15}, {-40, 0.2}, {20, 0.45},
                  {45, 0.7},  {60, 0.8}, {300, 0.9}, {700, 1.0}};
  s.ambient = 0.25;
  s.diffuse = 0.75;
  s.specular = 0.25;
  s.shininess = 12;
  s.light_falloff_mm = 1e9;
  s.show_labels = false;
  s.step_mm = step_mm;
  return s;
}

RenderSettings lap_settings(double step_mm) {
  RenderSettings s;
  s.tf = preset_transfer_function(RenderPreset::Laparoscopic);
  s.step_mm = step_mm;
  return s;
}

double g_setup_s = 0;  // shader compile + volume upload with its gradients (VTK's "setup_s" counterpart)

Renderer& gl_caster() {   // the render stage's GL path
  static std::unique_ptr<Renderer> gl;
  if (!gl) {
    bench();
    const auto t0 = std::chrono::steady_clock::now();
    gl = std::make_unique<Renderer>(false, GlBackend::Auto);
    gl->set_volume(bench().volume);
    g_setup_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  }
  return *gl;
}

// args: width, height, step in µm, 0 = laparoscopic preset / 1 = VTK's transfer function
void BM_RenderGl(benchmark::State& state) {
  const Bench& b = bench();
  Renderer& gl = gl_caster();
  ViewCamera cam = b.camera;
  cam.width = int(state.range(0));
  cam.height = int(state.range(1));
  const double step = state.range(2) / 1000.0;
  const RenderSettings s = state.range(3) ? vtk_like_settings(step) : lap_settings(step);
  RenderImage im = gl.render(cam, s);  // warm: shader compile, occupancy upload
  if (const char* dir = std::getenv("PNEUMO_BENCH_VTK_DIR"))
    write_view_png(std::string(dir) + "/pneumo_" + std::to_string(cam.width) + "x" + std::to_string(cam.height) + "_" +
                       (state.range(3) ? "vtktf" : "lap") + ".png",
                   im);
  for (auto _ : state) {
    im = gl.render(cam, s);
    benchmark::DoNotOptimize(im.rgba.data());
  }
  state.counters["fps"] = benchmark::Counter(double(state.iterations()), benchmark::Counter::kIsRate);
  state.counters["covered"] = image_stats(im).covered_fraction;
  state.counters["setup_s"] = g_setup_s;
  state.SetLabel(shared_gl_context().info().renderer);
}
BENCHMARK(BM_RenderGl)
    ->Args({512, 512, 375, 0})
    ->Args({1920, 1080, 375, 0})
    ->Args({512, 512, 500, 1})
    ->Args({512, 512, 375, 1})
    ->Args({1920, 1080, 500, 1})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MinTime(2.0);

// args as BM_RenderGl's
void BM_RenderCpuReference(benchmark::State& state) {
  const Bench& b = bench();
  ViewCamera cam = b.camera;
  cam.width = int(state.range(0));
  cam.height = int(state.range(1));
  const double step = state.range(2) / 1000.0;
  const RenderSettings s = state.range(3) ? vtk_like_settings(step) : lap_settings(step);
  Renderer reference(true, GlBackend::Auto);
  reference.set_volume(b.volume);
  RenderImage im;
  for (auto _ : state) {
    im = reference.render(cam, s);
    benchmark::DoNotOptimize(im.rgba.data());
  }
  state.counters["fps"] = benchmark::Counter(double(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_RenderCpuReference)
    ->Args({128, 128, 375, 0})
    ->Args({512, 512, 500, 1})
    ->Args({1920, 1080, 500, 1})
    ->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(1);

}  // namespace
