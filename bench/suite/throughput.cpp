#include "pipeline/scene_stages.h"
#include "suite/throughput.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>

#include "common/cpu_load.h"
#include "common/explicit_update.h"
#include "common/solver_cost.h"
#include "common/warp_cost.h"
#include "pipeline/render_scene.h"
#include "render/camera_model.h"
#include "render/gl_context.h"
#include "render/renderer.h"
#include "render/render_volume.h"
#include "render/transfer_function.h"
#include "solve/forces_cl.h"
#include "solve/solver.h"
#include "solve/solve_on_device.h"
#include "solve/solver_cl.h"
#include "warp/warp.h"
#include "warp/warp_mesh.h"

namespace pneumo::bench {

namespace {

using json = nlohmann::json;
using Clock = std::chrono::steady_clock;

/// Each timed repetition runs about this long (calls are batched to reach it), so short calls are not lost in
/// timer and launch noise.
double rep_target_s(const BenchContext& ctx) { return ctx.quick() ? 0.02 : 0.25; }
int reps(const BenchContext& ctx) { return ctx.quick() ? 2 : 5; }

/// A deterministic perturbed state (~0.1 mm, ~1 mm/s): nothing trivially zero (as bench_solver.cpp).
void perturbed_state(const Mesh& m, std::vector<Vec3>& x, std::vector<Vec3>& v) {
  const int64_t N = m.node_count();
  x = m.rest_m;
  v.assign(std::size_t(N), Vec3::Zero());
  for (int64_t n = 0; n < N; ++n) {
    const double a = std::sin(0.37 * double(n)), b = std::cos(0.61 * double(n)), s = std::sin(0.13 * double(n));
    x[n] += 1e-4 * Vec3(a, b, s);
    v[n] = 1e-3 * Vec3(b, s, a);
  }
}

/// Calls per repetition so one repetition lasts about rep_target_s.
int batch(const BenchContext& ctx, const std::function<void()>& once) {
  const auto t0 = Clock::now();
  once();
  const double t = std::max(seconds_since(t0), 1e-6);
  return std::clamp(int(rep_target_s(ctx) / t), 1, 10000);
}

/// Rates (calls per second) from seconds per batch of `calls`.
json rate_json(const Summary& seconds, double calls, double scale = 1.0) {
  Summary r;
  r.median = scale * calls / seconds.median;
  r.min = scale * calls / seconds.max;
  r.max = scale * calls / seconds.min;
  r.n = seconds.n;
  return to_json(r);
}

json roofline_json(const Roofline& r, const Cost& cost, double bw, double node_rate) {
  return {{"fraction", r.fraction}, {"bound", r.memory_bound ? "memory" : "compute"},
          {"bytes_per_node_update", cost.bytes}, {"flops_per_node_update", cost.flops},
          {"bandwidth_gb_s", bw}, {"bound_node_updates_per_s", r.bound_rate}, {"node_updates_per_s", node_rate}};
}

/// Force evaluations and explicit steps on one device.
json measure_forces_and_steps(BenchContext& ctx, const BenchCase& c, const Device& d) {
  const Mesh& m = c.mesh;
  const double N = double(m.node_count());
  const SolveOptions opt = solve_options_from_scene(c.scene);
  ForceModel model = opt.forces;
  const double dt = opt.dt_s > 0 ? opt.dt_s : opt.dt_safety * stable_time_step(m, model.damping);
  std::vector<Vec3> x0, v0;
  perturbed_state(m, x0, v0);
  const double bw = ctx.bandwidth_gb_s(d);
  json out;
  Summary forces_s, steps_s;
  int forces_k = 1, steps_k = 1;
  Cost force_cost, step_cost;
  double peak = 0;
  const CpuSample c0 = cpu_sample();
  if (!d.opencl()) {
    peak = cpu_peak_flop_s(d.threads);
    force_cost = cpu_force_cost(m, model);
    step_cost = cpu_step_cost(m, model);
    with_threads(d.threads, [&] {
      ForceEvaluator eval(m);
      std::vector<Vec3> f, x = x0, v = v0;
      const auto evaluate = [&] { eval.evaluate(model, x0, v0, f); };
      evaluate();   // allocates the per-element scratch
      forces_k = batch(ctx, evaluate);
      forces_s = time_reps(reps(ctx), 0, [&] { for (int i = 0; i < forces_k; ++i) evaluate(); });
      const auto step = [&] {
        eval.evaluate(model, x, v, f);
        bench::explicit_update(m, dt, f, x, v);
      };
      steps_k = batch(ctx, step);
      steps_s = time_reps(reps(ctx), 0, [&] { for (int i = 0; i < steps_k; ++i) step(); });
      for (const Vec3& p : x)
        if (!p.allFinite()) throw std::runtime_error("explicit steps diverged in the benchmark");
    });
  } else {
    ocl::Context& cl = ctx.cl(d);
    peak = cl_peak_flop_s(d.info);
    ClForceEvaluator eval(cl, m);
    eval.upload_state(x0, v0);
    auto& q = cl.queue();
    const auto evaluate = [&] { eval.evaluate(model); q.finish(); };
    evaluate();   // PoCL compiles each kernel at its first launch
    forces_k = batch(ctx, evaluate);
    forces_s = time_reps(reps(ctx), 0, [&] { for (int i = 0; i < forces_k; ++i) eval.evaluate(model); q.finish(); });
    force_cost = cl_force_cost(m, model, eval.spring_records_per_node(), 1.0);
    const auto free = ClForceEvaluator::Nodes::Free;
    step_cost = cl_step_cost(m, model, eval.spring_records_per_node(free), eval.gathered_fraction(free));
    ClExplicitStepper stepper(cl, m, model, dt);
    const auto step = [&] { stepper.steps(1); stepper.finish(); };
    step();
    steps_k = batch(ctx, step);
    steps_s = time_reps(reps(ctx), 0, [&] { stepper.steps(steps_k); stepper.finish(); });
  }
  const double other = other_cores(c0, cpu_sample());
  const double force_rate = forces_k / forces_s.median, step_rate = steps_k / steps_s.median;
  out["forces"] = {{"force_evals_per_s", rate_json(forces_s, forces_k)},
                   {"node_updates_per_s", rate_json(forces_s, forces_k, N)},
                   {"calls_per_repetition", forces_k},
                   {"roofline", roofline_json(roofline(force_rate * N, force_cost, bw, peak), force_cost, bw,
                                              force_rate * N)}};
  out["explicit_step"] = {{"steps_per_s", rate_json(steps_s, steps_k)},
                          {"node_updates_per_s", rate_json(steps_s, steps_k, N)},
                          {"calls_per_repetition", steps_k},
                          {"roofline", roofline_json(roofline(step_rate * N, step_cost, bw, peak), step_cost, bw,
                                                     step_rate * N)}};
  out["other_cores"] = other;
  return out;
}

/// The deformed CT as the renderer gets it from the pipeline (rounded to whole HU for an int16 CT, as
/// deformed_ct_volume writes it).
RenderVolume render_volume(const BenchCase& c, const WarpResult& w) {
  RenderVolume v;
  v.geometry = c.ct.geometry();
  v.hu = w.ct_hu;
  const bool int16 = c.ct.type() == VoxelType::Int16 || c.ct.type() == VoxelType::Int32;
  if (int16)
    for (float& h : v.hu) h = std::round(std::clamp(h, -32767.0f, 32767.0f));
  v.hu_is_int16 = int16;
  v.labels = w.labels;
  return v;
}

/// The scene's first camera; else an anterior exterior view of the volume's centre from 400 mm.
ViewCamera bench_camera(const BenchCase& c, int width, int height) {
  const ViewSettings& r = c.scene.render;
  if (!r.cameras.empty()) {
    const Camera& cam = r.cameras.front();
    return make_view_camera(look_at_pose(cam.position_mm, cam.look_at_mm, cam.optics.up), cam.optics, width, height);
  }
  const Geometry& g = c.ct.geometry();
  const Vec3 centre = g.to_world(Vec3(0.5 * double(g.dims[0] - 1), 0.5 * double(g.dims[1] - 1),
                                      0.5 * double(g.dims[2] - 1)));
  Optics o;
  o.fov_deg = 50;
  return make_view_camera(look_at_pose(centre + Vec3(0, 400, 0), centre, Vec3(0, 0, 1)), o, width, height);
}


}  // namespace

json measure_case_throughput(BenchContext& ctx, const BenchCase& c, int pipeline_reps) {
  json out;
  const MeshStats& st = c.mesh.stats;
  const Geometry& g = c.ct.geometry();
  out["case"] = c.name;
  out["grid"] = {g.dims[0], g.dims[1], g.dims[2]};
  out["spacing_mm"] = {g.spacing_mm.x(), g.spacing_mm.y(), g.spacing_mm.z()};
  const CubeVoxels& cube = c.mesh.cube_voxels;
  out["cube_voxels"] = cube.uniform() ? json(cube[0]) : json::array({cube[0], cube[1], cube[2]});
  out["nodes"] = st.nodes;
  out["springs"] = st.springs;
  out["tetrahedra"] = st.tetrahedra;
  out["cavity_faces"] = st.cavity_faces;
  out["solver"] = enum_name(c.scene.solver.method);
  out["seconds_input"] = c.seconds_input;
  out["seconds_roles"] = c.seconds_roles;
  out["seconds_mesh"] = c.seconds_mesh;

  const SolveOptions base = [&] {
    SolveOptions o = solve_options_from_scene(c.scene);
    o.progress = false;
    // A device without the case's scheme: the CPU solves it, and the row says so (solve.result.device).
    o.allow_cpu_fallback = true;
    return o;
  }();
  const int width = ctx.quick() ? 128 : c.scene.render.width, height = ctx.quick() ? 96 : c.scene.render.height;
  const ViewCamera camera = bench_camera(c, width, height);
  const RenderSettings settings = settings_from_scene(c.scene.render, c.ct.geometry());
  std::unique_ptr<Renderer> gl;   // the stage's GL path
  std::string gl_renderer;
  try {
    gl = std::make_unique<Renderer>(false, GlBackend::Auto);
    gl_renderer = gl->describe().value("gl_renderer", "");
  } catch (const std::exception& e) {
    ctx.note(c.name + ": no OpenGL context, frames not rendered (" + e.what() + ")");
  }
  const int64_t voxels = c.warp_box().voxel_count();
  WarpResult last_warp;

  json devices = json::array();
  for (const Device& d : ctx.devices()) {
    std::fprintf(stderr, "[bench] %s on %s\n", c.name.c_str(), d.name.c_str());
    json dj;
    dj["device"] = d.name;
    dj["description"] = d.description();
    dj["bandwidth_gb_s"] = ctx.bandwidth_gb_s(d);
    try {
      dj.update(measure_forces_and_steps(ctx, c, d));
      std::vector<double> solve_s, warp_s, render_s, total_s;
      json solve_info;
      const CpuSample c0 = cpu_sample();
      for (int rep = 0; rep < pipeline_reps; ++rep) {
        SolveResult r;
        WarpResult w;
        auto t0 = Clock::now();
        if (d.opencl()) r = solve_on_device(&ctx.cl(d), c.mesh, base);
        else with_threads(d.threads, [&] { r = solve_on_device(nullptr, c.mesh, base); });
        solve_s.push_back(seconds_since(t0));
        std::vector<Vec3> u(r.x.size());
        for (std::size_t n = 0; n < u.size(); ++n) u[n] = r.x[n] - c.mesh.rest_m[n];
        t0 = Clock::now();
        const WarpMesh wm = make_warp_mesh(c.mesh, u);
        if (d.opencl()) w = warp_on_device(&ctx.cl(d), wm, c.warp_source(), c.warp_box(), WarpOptions{});
        else with_threads(d.threads, [&] { w = warp_on_device(nullptr, wm, c.warp_source(), c.warp_box(), WarpOptions{}); });
        warp_s.push_back(seconds_since(t0));
        double frame = 0;
        if (gl) {
          t0 = Clock::now();
          const RenderVolume volume = render_volume(c, w);
          gl->set_volume(volume);
          gl->render(camera, settings);
          frame = seconds_since(t0);
        }
        render_s.push_back(frame);
        total_s.push_back(solve_s.back() + warp_s.back() + frame);
        solve_info = {{"steps", r.steps}, {"force_evaluations", r.force_evaluations}, {"converged", r.converged},
                      {"stop_reason", stop_reason_text(r.stop_reason)}, {"residual", r.residual}, {"device", r.device}};
        if (!r.device_fallback.empty() && rep == 0) {
          solve_info["device_fallback"] = r.device_fallback;
          ctx.note(c.name + " on " + d.name + ": the solve ran on the CPU (" + r.device_fallback + ")");
        }
        last_warp = std::move(w);
      }
      const Summary solve = summarize(solve_s), warp = summarize(warp_s);
      const double bw = dj["bandwidth_gb_s"];
      const double warp_rate = double(voxels) / warp.median;
      const double bytes = d.opencl() ? kWarpClBytesPerVoxel : kWarpCpuBytesPerVoxel;
      dj["solve"] = {{"seconds", to_json(solve)}, {"result", solve_info},
                     {"node_updates_per_s", double(c.mesh.node_count()) * double(solve_info["force_evaluations"].get<int64_t>()) / solve.median}};
      dj["warp"] = {{"seconds", to_json(warp)},
                    {"voxels", voxels},
                    {"voxels_per_s", rate_json(warp, double(voxels))},
                    {"roofline", {{"fraction", warp_rate / (bw * 1e9 / bytes)}, {"bound", "memory"},
                                  {"bytes_per_voxel", bytes}, {"bandwidth_gb_s", bw}}},
                    {"x_vtk", warp_rate / kVtkWarpVoxelsPerS}, {"x_itk", warp_rate / kItkWarpVoxelsPerS}};
      dj["render_upload_and_frame_s"] = to_json(summarize(render_s));
      // End to end: the case's roles and mesh (CPU, measured once when the case was built) + solve + warp +
      // uploading the deformed CT and rendering one frame, per pass.
      Summary e2e = summarize(total_s);
      const double prep = c.seconds_roles + c.seconds_mesh;
      e2e.median += prep;
      e2e.min += prep;
      e2e.max += prep;
      dj["end_to_end_s"] = to_json(e2e);
      dj["pipeline_other_cores"] = other_cores(c0, cpu_sample());
    } catch (const std::exception& e) {
      dj["error"] = e.what();
      ctx.note(c.name + " on " + d.name + ": " + e.what());
    }
    devices.push_back(dj);
  }
  out["devices"] = devices;

  // The renderer alone, on the last deformed CT: GL frames with the volume uploaded, and the CPU reference at a
  // quarter of the size (it is the checking oracle, not a fast path).
  json render;
  if (gl && !last_warp.ct_hu.empty()) {
    const RenderVolume volume = render_volume(c, last_warp);
    gl->set_volume(volume);
    gl->render(camera, settings);
    const int frames = ctx.quick() ? 2 : 4;
    const CpuSample c0 = cpu_sample();
    const Summary s = time_reps(reps(ctx), 0, [&] { for (int i = 0; i < frames; ++i) gl->render(camera, settings); });
    render["gl"] = {{"renderer", gl_renderer}, {"width", width}, {"height", height},
                    {"frames_per_s", rate_json(s, frames)}, {"other_cores", other_cores(c0, cpu_sample())}};
  }
  if (!last_warp.ct_hu.empty()) {
    const RenderVolume v = render_volume(c, last_warp);
    ViewCamera small = bench_camera(c, std::max(16, width / 4), std::max(12, height / 4));
    json cpu = json::array();
    for (const Device& d : ctx.devices()) {
      if (d.opencl()) continue;
      Summary s;
      Renderer reference(true, GlBackend::Auto);
      reference.set_volume(v);
      with_threads(d.threads, [&] { s = time_reps(ctx.quick() ? 1 : 2, 0, [&] { reference.render(small, settings); }); });
      cpu.push_back({{"device", d.name}, {"width", small.width}, {"height", small.height},
                     {"frames_per_s", rate_json(s, 1)}});
    }
    render["cpu_reference"] = cpu;
  }
  render["roofline"] = nullptr;
  render["roofline_note"] = "ray casting is bound by the sample rate of the renderer (llvmpipe's shader cores), "
                            "not by DRAM: no byte count is claimed";
  out["render"] = render;
  return out;
}

}  // namespace pneumo::bench
