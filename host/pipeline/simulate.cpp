#include "pipeline/simulate.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <sstream>

#include "core/atomic_file.h"
#include "core/stopwatch.h"
#include "core/error.h"
#include "core/log.h"
#include "core/units.h"
#include "core/thread_count.h"
#include "cl/cl_runtime.h"
#include "mesh/deformation_file.h"
#include "mesh/vtu_writer.h"
#include "pipeline/cavity_measures.h"
#include "pipeline/scene_stages.h"
#include "anatomy/anatomical_axes.h"
#include "report/plot_svg.h"
#include "solve/gravity_compensation.h"
#include "solve/solvable.h"
#include "solve/solve_on_device.h"
#include "solve/thorax_beyond_cut.h"

namespace pneumo {

namespace {
/// Anterior in world RAS is +y.
const Vec3 kAnterior(0.0, 1.0, 0.0);

void throw_if_stopped_inverted(const SolveResult& r, const Mesh& m, double target_mmhg) {
  if (r.stop_reason != StopReason::InvertedTetrahedra) return;
  char at[96];
  std::snprintf(at, sizeof at, "at step %lld (%.1f of %.1f mmHg)", (long long)r.steps,
                r.final_pressure_pa / units::kPaPerMmHg, target_mmhg);
  throw InvertedStopError(r.solver + " stopped " + at + ": " + std::to_string(r.inverted_tetrahedra) + " of " +
                          std::to_string(m.tets.size()) +
                          " tetrahedra turned inside out and solver.on_inverted is \"stop\"; lower "
                          "load.pressure_mmhg or raise material.young_kpa, or set solver.on_inverted to "
                          "\"continue\" to finish the run and count them");
}
}  // namespace

namespace {
// A device that cannot run the scene's solver is refused before the roles and the mesh, not after them
// (solve_on_device refuses it too, for callers that skip this).
void require_device_runs_solver(const Scene& scene) {
  if (!ocl::parse_device_spec(scene.device).use_opencl) return;
  try {
    require_device_solves(scene.device, solve_options_from_scene(scene));
  } catch (const InputError& e) {
    throw InputError("scene " + scene.path + ": " + e.what());
  }
}
}  // namespace

Simulation prepare_simulation(const Scene& scene, bool keep_inputs) {
  fit_threads_to_load();
  require_device_runs_solver(scene);
  Simulation sim;
  auto t0 = std::chrono::steady_clock::now();
  sim.roles = load_roles(scene, keep_inputs ? &sim.inputs : nullptr);
  sim.coverage = scan_coverage(sim.roles, scene.roles.label_names.empty() ? scene_label_names(scene) : scene.roles.label_names);
  sim.stage_seconds_roles = seconds_since(t0);
  log::info("scan: " + sim.coverage.summary);
  for (const std::string& w : sim.coverage.warnings) log::warn("scan: " + w);

  t0 = std::chrono::steady_clock::now();
  sim.mesh = build_scene_mesh(voxel_roles_of(sim.roles), scene, /*to_solve=*/true);
  sim.stage_seconds_mesh = seconds_since(t0);
  const MeshStats& s = sim.mesh.stats;
  std::ostringstream os;
  const Vec3 edge_mm = sim.mesh.cube_voxels.edge_mm(sim.mesh.grid.spacing_mm);
  os.precision(3);
  os << "mesh: cubes of " << sim.mesh.cube_voxels.text() << " voxels (" << edge_mm[0] << " × " << edge_mm[1] << " × "
     << edge_mm[2] << " mm), " << s.nodes << " nodes, " << s.tetrahedra << " tetrahedra, " << s.springs << " springs, "
     << s.cavity_faces << " cavity faces, " << s.fixed_nodes << " fixed nodes, " << s.doubled_cubes
     << " doubled cubes";
  if (s.cut_face_nodes > 0) os << ", " << s.cut_face_nodes << " nodes sliding on the CT's cut faces";
  if (s.thorax_nodes > 0) os << ", " << s.thorax_nodes << " opening onto the chest";
  log::info(os.str());
  // Before starting a device: nothing free, or a part the load would carry away.
  check_solvable(sim.mesh, solve_options_from_scene(scene), "scene " + scene.path);
  if (s.cavity_faces == 0)
    throw InputError("scene " + scene.path + ": the mesh has no cavity faces (no wall/viscera interface): the gas "
                     "has nowhere to act; check the role mapping (roles.*_labels) and mesh.model");
  return sim;
}

Simulation simulate_scene(const Scene& scene) {
  Simulation sim = prepare_simulation(scene);
  solve_simulation(scene, sim);
  return sim;
}

void solve_simulation(const Scene& scene, Simulation& sim, const SolveHooks& hooks) {
  fit_threads_to_load();
  const auto t0 = std::chrono::steady_clock::now();
  const ocl::DeviceSpec device = ocl::parse_device_spec(scene.device);
  std::shared_ptr<ocl::Context> ctx;
  if (device.use_opencl) ctx = ocl::Context::shared(device);
  SolveOptions base = solve_options_from_scene(scene);
  if (ctx && device_shortfall(base, &sim.mesh).empty()) log::info("solving on " + ctx->info().spec() + " " + ctx->info().name);
  // With gravity compensated the solver's rest shape is the unloaded one, and every solve starts at
  // the CT (its equilibrium under gravity); displacements stay measured from the CT (sim.mesh).
  std::optional<Mesh> unloaded;
  if (scene.material.gravity && scene.material.gravity_compensation) {
    UnloadedShape u = unloaded_shape(sim.mesh, base, [&](const Mesh& m, const SolveOptions& o, const std::vector<Vec3>& xs) {
      return solve_on_device(ctx.get(), m, o, xs);
    });
    sim.gravity = {true, u.sag_mm, u.error_mm, u.wall_time_s, u.iterations, u.solver_steps};
    unloaded = std::move(u.mesh);
  }
  const Mesh& solver_mesh = unloaded ? *unloaded : sim.mesh;
  auto run = [&](const SolveOptions& opt, const std::vector<Vec3>& x_start) {
    SolveResult r = solve_on_device(ctx.get(), solver_mesh, opt, x_start.empty() ? sim.mesh.rest_m : x_start);
    sim.device = r.device;
    sim.device_fallback = r.device_fallback;
    return r;
  };
  base.snapshot_every_steps = hooks.snapshot_every_steps;
  base.on_snapshot = hooks.on_snapshot;
  if (scene.load.pressure_curve_mmhg.empty()) {
    SolveOptions opt = base;
    opt.start_pressure_pa = hooks.start_pressure_pa;
    sim.result = run(opt, hooks.x_start);
    throw_if_stopped_inverted(sim.result, sim.mesh, scene.load.pressure_mmhg);
  } else {
    std::vector<double> pressures = scene.load.pressure_curve_mmhg;
    pressures.push_back(scene.load.pressure_mmhg);
    std::sort(pressures.begin(), pressures.end());
    pressures.erase(std::unique(pressures.begin(), pressures.end()), pressures.end());
    std::vector<Vec3> x = sim.mesh.rest_m;
    double previous_pa = 0.0;
    for (const double p_mmhg : pressures) {
      log::info("pressure-volume curve: " + std::to_string(p_mmhg) + " mmHg");
      SolveOptions opt = base;
      opt.forces.pressure_pa = units::mmhg_to_pa(p_mmhg);
      opt.start_pressure_pa = previous_pa;
      PressurePoint point;
      point.pressure_mmhg = p_mmhg;
      if (opt.forces.pressure_pa == previous_pa) {   // already in equilibrium here (0 mmHg at rest)
        point.converged = true;
      } else {
        SolveResult r = run(opt, x);
        throw_if_stopped_inverted(r, sim.mesh, p_mmhg);
        x = r.x;
        point.converged = r.converged;
        point.steps = r.steps;
        point.residual = r.residual;
        point.wall_time_s = r.wall_time_s;
        if (p_mmhg == scene.load.pressure_mmhg) sim.result = std::move(r);
      }
      const DeformationMetrics d = deformation_metrics(sim.mesh, x);
      point.cavity_volume_ml = d.cavity_volume_ml;
      point.anterior_rise_mm = d.anterior_rise_mm;
      sim.pressure_curve.push_back(point);
      previous_pa = opt.forces.pressure_pa;
    }
    if (sim.result.x.empty()) {   // load.pressure_mmhg was 0: the rest state
      sim.result.x = sim.mesh.rest_m;
      sim.result.v.assign(sim.mesh.rest_m.size(), Vec3::Zero());
      sim.result.converged = true;
      sim.result.stop_reason = StopReason::Converged;
      sim.result.solver = enum_name(base.method);
    }
  }
  sim.stage_seconds_solve = seconds_since(t0);
  // Gravity without contact: where the gas does not carry the wall's weight (below about 2-3 mmHg) the
  // wall sinks into the viscera it lies on, and the "cavity" closes below zero. Said, not hidden.
  if (scene.material.gravity && !scene.material.contact) {
    const double ml = deformation_metrics(sim.mesh, sim.result.x).cavity_volume_ml;
    if (ml < 0.0)
      log::warn("the cavity closed to " + std::to_string(int(ml)) + " ml: the pressure does not carry the wall's "
                "weight and the wall sank into the viscera; raise load.pressure_mmhg or set material.contact to true");
  }
}

DeformationMetrics deformation_metrics(const Mesh& m, const std::vector<Vec3>& x) {
  DeformationMetrics d;
  int64_t wall = 0, viscera = 0;
  for (int64_t n = 0; n < m.node_count(); ++n) {
    const Vec3 u = units::m_to_mm(1.0) * (x[n] - m.rest_m[n]);
    if (m.hold[n] == kHoldAll) d.max_fixed_displacement_mm = std::max(d.max_fixed_displacement_mm, u.norm());
    if (m.node_part[n] == Part::Wall) {
      d.max_wall_displacement_mm = std::max(d.max_wall_displacement_mm, u.norm());
      d.mean_wall_displacement_mm += u.norm();
      d.anterior_rise_mm = std::max(d.anterior_rise_mm, u.dot(kAnterior));
      ++wall;
    } else {
      d.mean_viscera_displacement_mm += u.norm();
      d.mean_viscera_anterior_mm += u.dot(kAnterior);
      ++viscera;
    }
  }
  if (wall) d.mean_wall_displacement_mm /= double(wall);
  if (viscera) {
    d.mean_viscera_displacement_mm /= double(viscera);
    d.mean_viscera_anterior_mm /= double(viscera);
  }
  d.anterior_viscera_posterior_motion_mm = mean_posterior_motion_of_anterior_viscera_mm(m, x);
  for (int64_t t = 0; t < int64_t(m.tets.size()); ++t) {
    if (m.tet_part[t] != Part::Viscera) continue;
    const auto& q = m.tets[t];
    const double v = signed_tet_volume(x[q[0]], x[q[1]], x[q[2]], x[q[3]]);
    d.viscera_volume_change_ml += m.tet_fraction[t] * (v - m.tet_rest_volume_m3[t]) * 1e6;   // m³ → ml
  }
  // Gas volume: the change of the volume the cavity surfaces enclose (divergence theorem; their
  // normals point out of their solids, into the gas). Where the CT's first or last slice cuts the
  // cavity off the surfaces are open; a field in the slices' planes gives those missing caps no flux
  // (mesh.h), so that cut costs nothing (with ⅓(x − centroid) it cost a tenth of the real CT's
  // cavity). Elsewhere the surfaces close, or open only where the wall and viscera stay bonded (the
  // attached interfaces), whose rims move together; the rest centroid as origin keeps what is left small.
  Vec3 centroid = Vec3::Zero();
  for (int32_t t : m.load_tet)
    for (int32_t n : m.tets[t]) centroid += m.rest_m[n] / 4.0;
  if (!m.load_tet.empty()) centroid /= double(m.load_tet.size());
  const Vec3 axial_normal = m.grid.direction.col(anatomical_axes(m.grid).axis[2]).normalized();
  d.cavity_volume_ml = (enclosed_cavity_volume(m, x, centroid, axial_normal) -
                        enclosed_cavity_volume(m, m.rest_m, centroid, axial_normal)) * 1e6;   // m³ → ml
  return d;
}

nlohmann::json simulation_metrics(const Scene& scene, const Simulation& sim) {
  const MeshStats& s = sim.mesh.stats;
  const SolveResult& r = sim.result;
  const DeformationMetrics d = deformation_metrics(sim.mesh, r.x);
  nlohmann::json j;
  j["pneumo_version"] = PNEUMO_VERSION;
  j["scene"] = scene.path;
  j["device"] = sim.device;
  j["device_requested"] = scene.device;
  if (!sim.device_fallback.empty()) j["device_fallback"] = sim.device_fallback;
  j["converged"] = r.converged;
  j["stop_reason"] = stop_reason_text(r.stop_reason);
  j["solver"] = r.solver;
  j["pressure_mmhg"] = r.final_pressure_pa / units::kPaPerMmHg;
  // As the scene writes it (one integer when every axis agrees), and the edge each axis gives in mm.
  const CubeVoxels& cube = sim.mesh.cube_voxels;
  j["cube_voxels"] = cube.uniform() ? nlohmann::json(cube[0]) : nlohmann::json::array({cube[0], cube[1], cube[2]});
  const Vec3 edge_mm = cube.edge_mm(sim.mesh.grid.spacing_mm);
  j["cube_edge_mm"] = {edge_mm[0], edge_mm[1], edge_mm[2]};
  const ScanCoverage& c = sim.coverage;
  j["scan_coverage"] = {{"summary", c.summary},
                        {"warnings", c.warnings},
                        {"top_cuts_body", c.top.cuts_body},
                        {"top_body_fraction", c.top.body_fraction},
                        {"top_structures", c.top.structures},
                        {"bottom_cuts_body", c.bottom.cuts_body},
                        {"bottom_body_fraction", c.bottom.body_fraction},
                        {"bottom_structures", c.bottom.structures},
                        {"lungs_in_view", c.lungs_in_view},
                        {"pelvis_in_view", c.pelvis_in_view},
                        {"wall_cut_laterally", c.wall_cut_laterally},
                        {"wall_cut_anteriorly", c.wall_cut_anteriorly}};
  j["nodes"] = s.nodes;
  j["tetrahedra"] = s.tetrahedra;
  j["springs"] = s.springs;
  j["cavity_faces"] = s.cavity_faces;
  j["pressure_tetrahedra"] = s.pressure_tetrahedra;
  j["fixed_nodes"] = s.fixed_nodes;
  j["cut_face_nodes"] = s.cut_face_nodes;
  if (!sim.mesh.thorax_node.empty()) {
    // The chest beyond the cranial cut (solve/thorax_beyond_cut.h): what the cut face pushed into it
    // and the pleural pressure that rose to meet it.
    const double dv_m3 = thorax_volume_change_m3(sim.mesh, r.x);
    j["thorax_nodes"] = s.thorax_nodes;
    j["thorax_compliance_l_per_cmh2o"] = sim.mesh.thorax_compliance_m3_per_pa / units::l_per_cmh2o_to_m3_per_pa(1.0);
    j["thorax_volume_change_ml"] = dv_m3 * 1e6;
    j["thorax_pressure_cmh2o"] = dv_m3 / sim.mesh.thorax_compliance_m3_per_pa / units::kPaPerCmH2O;
  }
  j["wall_cubes"] = s.wall_cubes;
  j["viscera_cubes"] = s.viscera_cubes;
  j["doubled_cubes"] = s.doubled_cubes;
  j["steps"] = r.steps;
  j["force_evaluations"] = r.force_evaluations;
  j["inner_iterations"] = r.inner_iterations;
  j["dt_ms"] = r.dt_s * 1e3;
  j["dt_stable_ms"] = r.dt_stable_s * 1e3;
  j["wall_time_s"] = r.wall_time_s;
  j["residual"] = r.residual;
  j["max_wall_displacement_mm"] = d.max_wall_displacement_mm;
  j["mean_wall_displacement_mm"] = d.mean_wall_displacement_mm;
  j["anterior_rise_mm"] = d.anterior_rise_mm;
  j["mean_viscera_displacement_mm"] = d.mean_viscera_displacement_mm;
  j["mean_viscera_anterior_displacement_mm"] = d.mean_viscera_anterior_mm;
  j["anterior_viscera_posterior_motion_mm"] = d.anterior_viscera_posterior_motion_mm;
  j["max_fixed_displacement_mm"] = d.max_fixed_displacement_mm;
  j["cavity_volume_ml"] = d.cavity_volume_ml;
  j["viscera_volume_change_ml"] = d.viscera_volume_change_ml;
  j["inverted_tetrahedra"] = r.inverted_tetrahedra;
  if (sim.gravity.done)
    j["gravity_compensation"] = {{"sag_mm", sim.gravity.sag_mm}, {"error_mm", sim.gravity.error_mm},
                                 {"solves", sim.gravity.iterations}, {"steps", sim.gravity.solver_steps},
                                 {"wall_time_s", sim.gravity.wall_time_s}};
  const std::array<double, 4> roles_ml = sim.roles.volumes_ml();
  j["roles_ml"] = {{"wall", roles_ml[std::size_t(Role::Wall)]},
                   {"viscera", roles_ml[std::size_t(Role::Viscera)]},
                   {"fixed", roles_ml[std::size_t(Role::Fixed)]}};
  j["stage_seconds"] = {{"roles", sim.stage_seconds_roles}, {"mesh", sim.stage_seconds_mesh},
                        {"solve", sim.stage_seconds_solve}};
  if (!sim.pressure_curve.empty()) {
    nlohmann::json curve = nlohmann::json::array();
    for (const PressurePoint& p : sim.pressure_curve)
      curve.push_back({{"pressure_mmhg", p.pressure_mmhg}, {"cavity_volume_ml", p.cavity_volume_ml},
                       {"anterior_rise_mm", p.anterior_rise_mm}, {"converged", p.converged}, {"steps", p.steps},
                       {"residual", p.residual}, {"wall_time_s", p.wall_time_s}});
    j["pressure_curve"] = curve;
  }
  return j;
}

std::string convergence_plot_svg(const SolveResult& r) {
  PlotSeries residual{"residual", {}, {}, "#d62728"}, displacement{"max displacement", {}, {}, "#1f77b4"},
      pressure{"pressure", {}, {}, "#2ca02c"};
  for (const auto& h : r.history) {
    residual.x.push_back(double(h.step));
    residual.y.push_back(h.residual);
    displacement.x.push_back(double(h.step));
    displacement.y.push_back(units::m_to_mm(h.max_displacement_m));
    pressure.x.push_back(double(h.step));
    pressure.y.push_back(h.pressure_pa / units::kPaPerMmHg);
  }
  PlotOptions a;
  a.title = "Convergence (" + r.solver + ")";
  a.x_label = "step";
  a.y_label = "residual (net / pressure force)";
  a.log_y = true;
  a.height_px = 300;
  PlotOptions b;
  b.x_label = "step";
  b.y_label = "max displacement (mm)";
  b.height_px = 240;
  PlotOptions c = b;
  c.y_label = "pressure (mmHg)";
  c.height_px = 200;
  return stack_svg({line_plot_svg({residual}, a), line_plot_svg({displacement}, b), line_plot_svg({pressure}, c)});
}

std::string pressure_curve_plot_svg(const std::vector<PressurePoint>& curve) {
  PlotSeries volume{"cavity volume", {}, {}, "#1f77b4", true}, rise{"anterior rise", {}, {}, "#ff7f0e", true};
  for (const PressurePoint& p : curve) {
    volume.x.push_back(p.pressure_mmhg);
    volume.y.push_back(p.cavity_volume_ml);
    rise.x.push_back(p.pressure_mmhg);
    rise.y.push_back(p.anterior_rise_mm);
  }
  PlotOptions a;
  a.title = "Pressure-volume curve";
  a.x_label = "pressure (mmHg)";
  a.y_label = "cavity volume (ml)";
  PlotOptions b;
  b.x_label = "pressure (mmHg)";
  b.y_label = "anterior rise (mm)";
  b.height_px = 300;
  return stack_svg({line_plot_svg({volume}, a), line_plot_svg({rise}, b)});
}

void write_simulation(const Scene& scene, const Simulation& sim, const std::string& dir) {
  std::filesystem::create_directories(dir);
  const auto path = [&](const char* name) { return (std::filesystem::path(dir) / name).string(); };
  if (scene.output.write_meshes) {
    write_vtu(sim.mesh, {}, path("mesh_initial.vtu"));
    write_vtu(sim.mesh, sim.result.x, path("mesh_deformed.vtu"));
  } else {
    // An earlier (--force) simulation's meshes would not be this one's.
    for (const char* name : {"mesh_initial.vtu", "mesh_deformed.vtu"}) std::filesystem::remove(path(name));
  }
  std::ostringstream csv;
  csv << "step,time_s,pressure_mmhg,residual,max_displacement_mm,max_speed_mm_s\n";
  for (const auto& h : sim.result.history)
    csv << h.step << "," << h.time_s << "," << h.pressure_pa / units::kPaPerMmHg << "," << h.residual << ","
        << units::m_to_mm(h.max_displacement_m) << "," << units::m_to_mm(h.max_speed_m_s) << "\n";
  write_text_file_atomic(path("convergence.csv"), csv.str());
  write_text_file_atomic(path("convergence.svg"), convergence_plot_svg(sim.result));
  write_text_file_atomic(path("scene_used.json"), scene.echo().dump(2) + "\n");
  if (!sim.pressure_curve.empty()) {
    std::ostringstream pv;
    pv << "pressure_mmhg,cavity_volume_ml,anterior_rise_mm,converged,steps,residual\n";
    for (const PressurePoint& p : sim.pressure_curve)
      pv << p.pressure_mmhg << "," << p.cavity_volume_ml << "," << p.anterior_rise_mm << "," << p.converged << ","
         << p.steps << "," << p.residual << "\n";
    write_text_file_atomic(path("pressure_volume.csv"), pv.str());
    write_text_file_atomic(path("pressure_volume.svg"), pressure_curve_plot_svg(sim.pressure_curve));
  }
  // The solved shape for `pneumo warp` and later stages (deformation_file.h).
  Deformation def;
  def.displacement_m = displacements(sim.mesh, sim.result.x);
  def.pressure_pa = sim.result.final_pressure_pa;
  def.converged = sim.result.converged;
  write_deformation(path("deformation.bin"), sim.mesh, def);
  // metrics.json last: its presence says the run finished.
  write_text_file_atomic(path("metrics.json"), simulation_metrics(scene, sim).dump(2) + "\n");
}

}  // namespace pneumo
