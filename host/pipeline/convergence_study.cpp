#include "pipeline/convergence_study.h"

#include <algorithm>
#include <cmath>

#include "core/error.h"
#include "core/log.h"
#include "pipeline/simulate.h"
#include "solve/forces.h"

namespace pneumo {

ObservedOrder observed_order(const std::vector<double>& h, const std::vector<double>& f) {
  ObservedOrder o;
  const std::size_t n = h.size();
  if (n < 3 || f.size() != n) {
    o.extrapolated = f.empty() ? 0.0 : f.back();
    return o;
  }
  // The three finest: h1 < h2 < h3 (given coarse to fine, so reversed).
  const double h1 = h[n - 1], h2 = h[n - 2], h3 = h[n - 3];
  const double f1 = f[n - 1], f2 = f[n - 2], f3 = f[n - 3];
  const double d21 = f2 - f1, d32 = f3 - f2;
  o.extrapolated = f1;
  if (d21 == 0.0 || d32 == 0.0 || (d21 > 0) != (d32 > 0)) return o;
  // (f3 − f2)/(f2 − f1) = (h3ᵖ − h2ᵖ)/(h2ᵖ − h1ᵖ): the right side grows with p; bisection on [0.05, 8].
  const double target = d32 / d21;
  auto ratio = [&](double p) { return (std::pow(h3, p) - std::pow(h2, p)) / (std::pow(h2, p) - std::pow(h1, p)); };
  double lo = 0.05, hi = 8.0;
  if (target < ratio(lo) || target > ratio(hi)) return o;
  for (int it = 0; it < 200; ++it) {
    const double mid = 0.5 * (lo + hi);
    (ratio(mid) < target ? lo : hi) = mid;
  }
  o.order = 0.5 * (lo + hi);
  o.monotone = true;
  o.extrapolated = f1 - d21 * std::pow(h1, o.order) / (std::pow(h2, o.order) - std::pow(h1, o.order));
  return o;
}

ConvergenceStudy convergence_study(const Scene& scene, const std::vector<int>& cube_voxels) {
  if (cube_voxels.size() < 2) throw InputError("validate convergence: give at least 2 cube sizes (--cube-voxels)");
  for (std::size_t i = 0; i < cube_voxels.size(); ++i) {
    if (cube_voxels[i] < 1) throw InputError("validate convergence: every --cube-voxels value must be at least 1");
    if (i > 0 && cube_voxels[i] >= cube_voxels[i - 1])
      throw InputError("validate convergence: list --cube-voxels from coarse to fine (decreasing), e.g. 4,3,2,1");
  }
  ConvergenceStudy s;
  std::vector<double> h, rise, volume, wall, viscera;
  // The working grid's spacing (the CT's: padding adds voxels, not spacing), for cubes of L coarsest voxels in mm
  // with every axis near it. On an isotropic grid that is L on every axis, as the study always meshed.
  const Vec3 spacing_mm = load_roles(scene).geometry.spacing_mm;
  for (const int L : cube_voxels) {
    Scene sc = scene;
    sc.mesh.cube_mm = L * spacing_mm.maxCoeff();
    log::info("convergence: cube_voxels " + std::to_string(L) + " along the coarsest axis");
    const Simulation sim = simulate_scene(sc);
    const DeformationMetrics d = deformation_metrics(sim.mesh, sim.result.x);
    ConvergenceRow r;
    r.cube_voxels = L;
    r.cube = sim.mesh.cube_voxels;
    r.cube_edge_mm = r.cube.edge_mm(sim.roles.geometry.spacing_mm);
    r.cube_mm = L * sim.roles.geometry.spacing_mm.maxCoeff();
    r.anterior_rise_mm = d.anterior_rise_mm;
    r.cavity_volume_ml = d.cavity_volume_ml;
    r.mean_wall_displacement_mm = d.mean_wall_displacement_mm;
    r.viscera_posterior_motion_mm = d.anterior_viscera_posterior_motion_mm;
    r.nodes = sim.mesh.node_count();
    r.inverted = count_inverted(sim.mesh, sim.result.x);
    r.steps = sim.result.steps;
    r.converged = sim.result.converged;
    r.solve_seconds = sim.stage_seconds_solve;
    s.rows.push_back(r);
    h.push_back(r.cube_mm);
    rise.push_back(r.anterior_rise_mm);
    volume.push_back(r.cavity_volume_ml);
    wall.push_back(r.mean_wall_displacement_mm);
    viscera.push_back(r.viscera_posterior_motion_mm);
  }
  s.rise = observed_order(h, rise);
  s.volume = observed_order(h, volume);
  s.wall = observed_order(h, wall);
  s.viscera = observed_order(h, viscera);
  const std::size_t n = s.rows.size();
  auto change = [&](double coarse, double fine) { return fine != 0.0 ? std::abs(coarse - fine) / std::abs(fine) : 0.0; };
  s.finest_change_rise = change(rise[n - 2], rise[n - 1]);
  s.finest_change_volume = change(volume[n - 2], volume[n - 1]);
  return s;
}

nlohmann::json to_json(const ConvergenceStudy& s) {
  nlohmann::json rows = nlohmann::json::array();
  for (const ConvergenceRow& r : s.rows)
    rows.push_back({{"cube_voxels", r.cube_voxels},
                    {"cube_voxels_per_axis", {r.cube[0], r.cube[1], r.cube[2]}},
                    {"cube_mm", r.cube_mm},
                    {"cube_edge_mm", {r.cube_edge_mm[0], r.cube_edge_mm[1], r.cube_edge_mm[2]}},
                    {"anterior_rise_mm", r.anterior_rise_mm},
                    {"cavity_volume_ml", r.cavity_volume_ml},
                    {"mean_wall_displacement_mm", r.mean_wall_displacement_mm},
                    {"anterior_viscera_posterior_motion_mm", r.viscera_posterior_motion_mm},
                    {"nodes", r.nodes},
                    {"inverted_tetrahedra", r.inverted},
                    {"steps", r.steps},
                    {"converged", r.converged},
                    {"solve_seconds", r.solve_seconds}});
  auto order = [](const ObservedOrder& o) {
    return nlohmann::json{{"observed_order", o.monotone ? nlohmann::json(o.order) : nlohmann::json(nullptr)},
                          {"extrapolated", o.extrapolated},
                          {"monotone", o.monotone}};
  };
  return {{"rows", rows},
          {"anterior_rise_mm", order(s.rise)},
          {"cavity_volume_ml", order(s.volume)},
          {"mean_wall_displacement_mm", order(s.wall)},
          {"anterior_viscera_posterior_motion_mm", order(s.viscera)},
          {"finest_change_rise", s.finest_change_rise},
          {"finest_change_volume", s.finest_change_volume}};
}

}  // namespace pneumo
