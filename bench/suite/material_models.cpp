#include "pipeline/scene_stages.h"
#include "suite/material_models.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>

#include "pipeline/simulate.h"
#include "scene/scene_presets.h"
#include "solve/fem_force_field_cl.h"
#include "solve/force_field.h"
#include "solve/solve_on_device.h"
#include "solve/solver.h"
#include "suite/bench_cases.h"
#include "validate/validate.h"

namespace pneumo::bench {

namespace {

using json = nlohmann::json;
using Clock = std::chrono::steady_clock;

struct ModelCase {
  MaterialModel model;
  double poisson;
};

// The springs' ν is 1/4 whatever is asked; the elements at 1/4 (the springs' own) and 0.45 (muscle and
// organs, nearly incompressible).
const ModelCase kLameModels[] = {{MaterialModel::Msd, 0.25},
                                 {MaterialModel::FemCorotational, 0.25},
                                 {MaterialModel::FemCorotational, 0.45},
                                 {MaterialModel::FemNeoHookean, 0.25},
                                 {MaterialModel::FemNeoHookean, 0.45}};

json lame_row(const ModelCase& mc, double cube_mm, const std::string& device) {
  LameOptions o;
  o.model = mc.model;
  o.poisson = mc.poisson;
  o.cube_mm = cube_mm;
  o.placements = 1;
  o.device = device;
  const LameResult r = validate_lame_sphere(o);
  return {{"model", enum_name(mc.model)}, {"poisson_ratio", mc.poisson}, {"cube_mm", cube_mm}, {"device", device},
          {"rel_error_inner", r.rel_error_inner}, {"rel_error_outer", r.rel_error_outer}, {"nodes", r.nodes},
          {"steps", r.steps}, {"wall_s", r.wall_time_s}};
}

json measure_lame(BenchContext& ctx) {
  json rows = json::array();
  const std::vector<double> cubes = ctx.quick() ? std::vector<double>{10.0} : std::vector<double>{10.0, 5.0};
  for (const ModelCase& mc : kLameModels) {
    if (ctx.quick() && mc.poisson == 0.25 && mc.model != MaterialModel::Msd) continue;
    for (double cube : cubes) {
      std::fprintf(stderr, "[bench] models: Lame sphere, %s nu %.2f, %.0f mm cubes, cpu\n", enum_name(mc.model),
                   mc.poisson, cube);
      rows.push_back(lame_row(mc, cube, "cpu"));
    }
    // The elements on each OpenCL device, at the coarse cube (the fine one is minutes on a CPU device).
    if (mc.model == MaterialModel::Msd) continue;
    for (const Device& d : ctx.devices())
      if (d.opencl()) {
        std::fprintf(stderr, "[bench] models: Lame sphere, %s nu %.2f, 10 mm cubes, %s\n", enum_name(mc.model),
                     mc.poisson, d.name.c_str());
        rows.push_back(lame_row(mc, 10.0, d.info.spec()));
      }
  }
  return rows;
}

struct TimeLimit {};

json real_ct_row(BenchCase& c, int cube_voxels, SolverMethod method, double limit_s) {
  if (c.mesh.cube_voxels != cube_voxels) remesh(c, cube_voxels);
  Scene scene = c.scene;
  scene.solver.method = method;
  SolveOptions opt = solve_options_from_scene(scene);
  opt.progress = false;
  const auto t0 = Clock::now();
  opt.snapshot_every_steps = 1;
  opt.on_snapshot = [&](const SolverSnapshot&) {
    if (seconds_since(t0) > limit_s) throw TimeLimit{};
  };
  json row = {{"model", enum_name(scene.material.model)}, {"solver", enum_name(method)},
              {"cube_voxels", cube_voxels}, {"cube_mm", cube_voxels * c.roles.geometry.spacing_mm.maxCoeff()},
              {"nodes", c.mesh.node_count()}, {"tetrahedra", c.mesh.tets.size()}};
  try {
    SolveResult r;
    with_threads(0, [&] { r = solve_on_device(nullptr, c.mesh, opt); });
    const DeformationMetrics d = deformation_metrics(c.mesh, r.x);
    row["wall_s"] = seconds_since(t0);
    row["converged"] = r.converged;
    row["stop_reason"] = stop_reason_text(r.stop_reason);
    row["steps"] = r.steps;
    row["inner_iterations"] = r.inner_iterations;
    row["inverted_tetrahedra"] = r.inverted_tetrahedra;
    row["anterior_rise_mm"] = d.anterior_rise_mm;
    row["cavity_volume_ml"] = d.cavity_volume_ml;
    row["viscera_posterior_motion_mm"] = d.anterior_viscera_posterior_motion_mm;
    const double viscera_ml = c.roles.volume_ml(Role::Viscera);
    if (viscera_ml > 0.0) row["viscera_volume_change_fraction"] = d.viscera_volume_change_ml / viscera_ml;
  } catch (const TimeLimit&) {
    row["wall_s"] = seconds_since(t0);
    row["converged"] = false;
    row["stop_reason"] = "time limit of the benchmark (" + std::to_string(int(limit_s)) + " s)";
  } catch (const DivergedError& e) {
    // A row, not the end of the benchmark: which solver fails on which model is what this table is for.
    row["wall_s"] = seconds_since(t0);
    row["converged"] = false;
    row["stop_reason"] = std::string("diverged: ") + e.what();
  }
  return row;
}

json measure_real_ct(BenchContext& ctx, const std::string& springs_scene, const std::string& fem_scene) {
  if (ctx.quick()) {
    ctx.note("material_models: --quick leaves out the real CT");
    return json::array();
  }
  std::string why;
  std::optional<BenchCase> springs = scene_case(springs_scene, "real_ct", why);
  std::optional<BenchCase> fem = springs ? scene_case(fem_scene, "real_ct_fem", why) : std::nullopt;
  if (!springs || !fem) {
    ctx.note("material_models: real CT skipped: " + why);
    return json::array();
  }
  constexpr double kLimitS = 300;
  json rows = json::array();
  const double spacing = springs->roles.geometry.spacing_mm.maxCoeff();
  // A model and solver that failed at a coarser preset (diverged or out of time) are not run at the finer
  // ones, where they have only more nodes and a worse condition: up to 300 s a row spent on a known answer.
  std::map<std::pair<std::string, std::string>, std::string> failed_at;
  for (const ScenePreset p : {ScenePreset::Preview, ScenePreset::Balanced, ScenePreset::Accurate}) {
    const int L = std::max(1, int(std::lround(preset_settings(p).cube_mm / spacing)));
    struct Run {
      BenchCase* c;
      SolverMethod method;
    };
    for (const Run run : {Run{&*springs, SolverMethod::Static}, Run{&*fem, SolverMethod::Newton},
                          Run{&*fem, SolverMethod::Static}}) {
      const std::pair<std::string, std::string> key{enum_name(run.c->scene.material.model), enum_name(run.method)};
      json row;
      if (const auto it = failed_at.find(key); it != failed_at.end()) {
        row = {{"model", key.first}, {"solver", key.second}, {"cube_voxels", L}, {"cube_mm", L * spacing},
               {"nodes", nullptr}, {"wall_s", nullptr}, {"converged", false},
               {"stop_reason", "not run: it did not converge at the coarser " + it->second + " preset"}};
      } else {
        std::fprintf(stderr, "[bench] models: real CT, %s, %s, L = %d\n", key.first.c_str(), key.second.c_str(), L);
        row = real_ct_row(*run.c, L, run.method, kLimitS);
        if (!row["converged"].get<bool>()) failed_at[key] = enum_name(p);
      }
      row["preset"] = enum_name(p);
      rows.push_back(row);
    }
  }
  return rows;
}

// Bytes each tetrahedron's kernels read and write once per call (fem_forces.cl), counted once: states (4 node
// displacements, its nodes, D_m⁻¹, constants; the state out), forces (state, D_m⁻¹, constants, group and ē; 4
// forces out), the group average (weight and e) and the gather (4 force entries and their indices). The
// product: δF (direction, nodes, D_m⁻¹, the rotation; δF out), the group average, the forces' change (state,
// D_m⁻¹, constants, ē, δē, δF; 4 forces out) and the gather.
constexpr double kEvaluateBytesPerTet = (64 + 16 + 36 + 16 + 160) + (160 + 36 + 16 + 8 + 64) + 8 + (64 + 16);
constexpr double kProductBytesPerTet = (64 + 16 + 36 + 36 + 40) + 8 + (160 + 36 + 16 + 8 + 40 + 64) + (64 + 16);

json measure_throughput(BenchContext& ctx) {
  BenchCase c = phantom_case(PhantomSize::Small, ctx.quick() ? 4 : 0);
  c.scene.material = SceneMaterial{};   // the default: neo-Hookean elements with Demiray's b = 10
  remesh(c, c.mesh.cube_voxels);
  ForceModel model = solve_options_from_scene(c.scene).forces;
  model.damping = false;
  const double T = double(c.mesh.tets.size());
  std::vector<Vec3> dir(c.mesh.node_count(), Vec3(1e-4, -2e-4, 3e-4)), f, kp;
  const int reps = ctx.quick() ? 3 : 10;
  json rows = json::array();
  for (const Device& d : ctx.devices()) {
    std::unique_ptr<ForceField> field =
        d.opencl() ? make_fem_force_field_cl(ctx.cl(d), c.mesh, model.material) : make_force_field(c.mesh, model);
    Summary eval, product;
    // Each evaluation at a new state (states are cached per position): alternate two.
    std::vector<Vec3> a = c.mesh.rest_m, b = c.mesh.rest_m;
    for (auto& x : b) x *= 1.001;
    bool flip = false;
    with_threads(d.threads, [&] {
      eval = time_reps(reps, 1, [&] {
        field->evaluate(model, flip ? a : b, {}, f);
        flip = !flip;
      });
      field->linearize(model, b);
      product = time_reps(reps, 1, [&] { field->stiffness_product(dir, kp); });
    });
    json row = {{"device", d.name}, {"description", d.description()}, {"tetrahedra", T},
                {"evaluate_s", to_json(eval)}, {"product_s", to_json(product)},
                {"evaluate_element_updates_per_s", T / eval.median},
                {"product_element_updates_per_s", T / product.median}};
    if (d.opencl()) {
      const double triad = ctx.bandwidth_gb_s(d);
      row["bytes_per_tet_evaluate"] = kEvaluateBytesPerTet;
      row["bytes_per_tet_product"] = kProductBytesPerTet;
      row["evaluate_fraction_of_triad"] = kEvaluateBytesPerTet * T / eval.median / (triad * 1e9);
      row["product_fraction_of_triad"] = kProductBytesPerTet * T / product.median / (triad * 1e9);
    } else {
      row["roofline"] = "the CPU reference works in double on its own element states: its bytes are not the "
                        "kernels'; compare its updates per second only";
    }
    rows.push_back(row);
  }
  return {{"case", c.name}, {"model", "fem-neohookean, b = 10, nu " + std::to_string(c.scene.material.poisson_ratio)},
          {"nodes", c.mesh.node_count()}, {"rows", rows},
          {"peer", {{"source", "SofaCUDA TetrahedronFEM as published: 2.6 ms per implicit "
                               "Euler step at 19 k nodes on an RTX 2070"},
                    {"nodes", 19000}, {"ms_per_step", 2.6},
                    {"comparable", "not directly: a step there holds its CG iterations (each a product like "
                                   "product_s here) and one evaluation; the peer is the order of magnitude a GPU "
                                   "reaches, not a ratio"}}}};
}

// Adult figures at 12–15 mmHg (docs/fidelity.md §4): an anterior rise of 25–60 mm, 1.5–4 L of gas, and
// viscera that keep their tissue volume within 5 % (organs and bowel contents do not lose volume under
// 1.6 kPa; the liver's blood, 12 % of the liver, is under 3 % of the viscera: docs/fidelity.md, "The
// viscera's volume").
bool within_human_figures(const json& r) {
  return r.contains("viscera_volume_change_fraction") && r["anterior_rise_mm"].get<double>() >= 25.0 &&
         r["anterior_rise_mm"].get<double>() <= 60.0 && r["cavity_volume_ml"].get<double>() >= 1500.0 &&
         r["cavity_volume_ml"].get<double>() <= 4000.0 &&
         std::abs(r["viscera_volume_change_fraction"].get<double>()) <= 0.05;
}

// Which model a user should pick at each preset, from the measurements: of the real-CT rows at that preset's
// cube size that converged with 0 inverted tetrahedra and lie within the adult figures, the fastest; and whether
// the default model (a scene that names none) is it.
json pick_model(const json& real_ct, const std::string& preset) {
  const json* pick = nullptr;
  for (const auto& r : real_ct) {
    if (r["preset"] != preset || !r["converged"].get<bool>() || r["inverted_tetrahedra"].get<int64_t>() != 0 ||
        !within_human_figures(r))
      continue;
    if (!pick || r["wall_s"].get<double>() < (*pick)["wall_s"].get<double>()) pick = &r;
  }
  const std::string default_model = enum_name(SceneMaterial{}.model);
  if (!pick) return {{"model", nullptr}, {"default_model", default_model}, {"default_follows", nullptr}};
  return {{"model", (*pick)["model"]}, {"solver", (*pick)["solver"]}, {"wall_s", (*pick)["wall_s"]},
          {"default_model", default_model}, {"default_follows", (*pick)["model"] == default_model}};
}

// The rule: the material model is the scene's physics, chosen by the user from the Lamé and real-CT tables; a preset
// sets the cube size and, for each model, the solver. For each preset's cube size and each model, the benchmark's
// pick is the fastest solver whose real-CT solve converged with 0 inverted tetrahedra; "follows" says whether the
// preset's solver for that model (scene_presets.h) is that pick.
json choose(const json& real_ct) {
  json out = json::array();
  for (const ScenePreset sp : {ScenePreset::Preview, ScenePreset::Balanced, ScenePreset::Accurate}) {
    const std::string preset = enum_name(sp);
    json per_model = json::array();
    for (const MaterialModel model : {MaterialModel::Msd, MaterialModel::FemNeoHookean}) {
      const std::string name = enum_name(model);
      const json* pick = nullptr;
      for (const auto& r : real_ct) {
        if (r["preset"] != preset || r["model"] != name || !r["converged"].get<bool>() ||
            r["inverted_tetrahedra"].get<int64_t>() != 0)
          continue;
        if (!pick || r["wall_s"].get<double>() < (*pick)["wall_s"].get<double>()) pick = &r;
      }
      const std::string preset_solver = enum_name(preset_method(preset_settings(sp), model));
      json m = {{"model", name}, {"preset_solver", preset_solver}};
      if (pick) {
        m["fastest"] = {{"solver", (*pick)["solver"]}, {"wall_s", (*pick)["wall_s"]}};
        m["follows"] = (*pick)["solver"] == preset_solver;
      } else {
        m["fastest"] = nullptr;
        m["follows"] = nullptr;
      }
      per_model.push_back(m);
    }
    out.push_back({{"preset", preset}, {"models", per_model}, {"model_pick", pick_model(real_ct, preset)}});
  }
  return out;
}

}  // namespace

json measure_material_models(BenchContext& ctx, const std::string& springs_scene, const std::string& fem_scene) {
  json out;
  out["lame"] = measure_lame(ctx);
  out["real_ct"] = measure_real_ct(ctx, springs_scene, fem_scene);
  out["throughput"] = measure_throughput(ctx);
  out["choice_rule"] =
      "the model is the scene's physics; per preset cube size and model, the fastest solver whose real-CT solve "
      "converged with 0 inverted tetrahedra, and whether the preset's solver for that model is it";
  out["choice"] = choose(out["real_ct"]);
  return out;
}

}  // namespace pneumo::bench
