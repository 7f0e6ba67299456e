#include <iostream>

#include "cli/commands.h"
#include "cli/device_option.h"
#include "core/atomic_file.h"
#include "core/error.h"
#include "pipeline/convergence_study.h"
#include "pipeline/pressure_volume_study.h"
#include "pipeline/view_resolution_study.h"
#include "validate/validate.h"

namespace pneumo::cli {

Run add_validate(CLI::App& app) {
  auto* cmd = app.add_subcommand("validate", "Check the physics against closed-form truths on this machine");
  cmd->require_subcommand(1);
  struct Opts {
    bool json = false;
    int across = 6;
    LameOptions lame;
    std::string lame_model = "msd";
    bool per_tetrahedron = false;
    std::string scene;
    std::vector<int> cube_voxels{4, 3, 2, 1};
    std::vector<double> pressures = default_pressure_volume_pressures();
    ViewResolutionOptions views;
    std::vector<std::string> sizes{"small", "medium", "large"};
    bool cpu_render = false;
  };
  auto o = std::make_shared<Opts>();
  auto* lattice = cmd->add_subcommand("lattice", "Effective Young's modulus of the cube lattice along an axis (method.md §4: 1.140·E)");
  lattice->add_option("--cubes", o->across, "Cubes across the block (even, >= 4)")->capture_default_str();
  lattice->add_flag("--json", o->json, "Print JSON (key young_ratio_axis)");
  auto* lame = cmd->add_subcommand("lame-sphere", "Hollow sphere under internal pressure against Lamé's solution (method.md §10)");
  lame->add_option("--cube-mm", o->lame.cube_mm, "Cube size in mm")->capture_default_str()->check(CLI::Range(1.0, 50.0));
  lame->add_option("--placements", o->lame.placements, "Positions of the sphere's centre relative to the lattice, averaged")
      ->capture_default_str()->check(CLI::Range(1, 64));
  lame->add_option("--model", o->lame_model, "Material model: msd, fem-corotational or fem-neohookean")
      ->capture_default_str()
      ->check(CLI::IsMember({"msd", "fem-corotational", "fem-neohookean"}));
  lame->add_option("--poisson", o->lame.poisson, "Poisson's ratio of the finite elements (the springs' is 1/4)")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 0.49));
  lame->add_option("--voxel-mm", o->lame.voxel_mm, "Voxel size of the sphere's image (0: a quarter of the cube; the cube size itself: a staircase of whole cubes)")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 50.0));
  lame->add_option("--pressure-mmhg", o->lame.pressure_mmhg,
                   "Internal pressure; solved at a hundredth of it and scaled back, since the closed form is linear")
      ->capture_default_str()
      ->check(CLI::Range(0.1, 60.0));
  lame->add_flag("--per-tetrahedron", o->per_tetrahedron,
                 "FEM: the dilatation per tetrahedron instead of averaged per cube (shows volumetric locking)");
  add_device_option(lame, o->lame.device, "Where the sphere is solved (the FEM models' Newton and the springs' static solver run on OpenCL)")
      ->capture_default_str();
  lame->add_flag("--json", o->json, "Print JSON (u_inner_mm, u_inner_analytic_mm, rel_error_inner, ...)");
  auto* conv = cmd->add_subcommand(
      "convergence", "One scene solved with several cube sizes: rise, cavity and wall displacement, with the observed order");
  conv->add_option("scene", o->scene, "Scene .json")->required();
  conv->add_option("--cube-voxels", o->cube_voxels, "Cube sizes in voxels along the CT's coarsest axis, coarse to fine (the other axes near-cubic)")
      ->delimiter(',')
      ->capture_default_str();
  conv->add_flag("--json", o->json, "Print JSON (rows, observed_order and extrapolated value per quantity)");
  auto* pv = cmd->add_subcommand("pressure-volume",
                                 "The cavity volume against pressure: compliance and the share of the 30 mmHg volume at 15");
  pv->add_option("scene", o->scene, "Scene .json")->required();
  pv->add_option("--pressures-mmhg", o->pressures, "Pressures, each solved from the last equilibrium (must hold 5, 15, 30)")
      ->delimiter(',')
      ->capture_default_str();
  pv->add_flag("--json", o->json, "Print JSON (curve, compliance_ml_per_mmhg, fraction_of_30_at_15)");
  auto* vr = cmd->add_subcommand(
      "view-resolution",
      "The phantom rendered at 4, 1.5 and 0.75 mm from the same cameras: SSIM and PSNR of each view against the finest");
  vr->add_option("--out", o->views.out_dir, "Folder for the views, the solved case and study.json")
      ->default_val("out/view_resolution");
  vr->add_option("--sizes", o->sizes, "Phantom sizes, coarse to fine; the last is the reference")
      ->delimiter(',')
      ->capture_default_str()
      ->check(CLI::IsMember({"small", "medium", "large"}));
  vr->add_option("--width", o->views.width, "View width in pixels")->capture_default_str()->check(CLI::Range(32, 4096));
  vr->add_option("--height", o->views.height, "View height in pixels")->capture_default_str()->check(CLI::Range(32, 4096));
  vr->add_flag("--cpu-render", o->cpu_render, "Render with the CPU reference instead of OpenGL (slow)");
  vr->add_flag("--force", o->views.force, "Replace the study.json of an earlier study in --out");
  vr->add_flag("--write-volumes", o->views.write_volumes,
               "Also write the volumes and cameras a peer renderer needs (bench/peers/vtk_view_resolution.py)");
  vr->add_flag("--json", o->json, "Print JSON (rows of view, size, shading, ssim, psnr_db)");
  return [=] {
    if (vr->parsed()) {
      o->views.sizes.clear();
      for (const std::string& n : o->sizes) o->views.sizes.push_back(parse_phantom_size(n));
      for (std::size_t i = 1; i < o->views.sizes.size(); ++i)
        if (phantom_geometry(o->views.sizes[i]).spacing_mm.maxCoeff() >=
            phantom_geometry(o->views.sizes[i - 1]).spacing_mm.maxCoeff())
          throw InputError("validate view-resolution: list --sizes from coarse to fine, e.g. small,medium,large");
      o->views.cpu_reference = o->cpu_render;
      const ViewResolutionStudy s = view_resolution_study(o->views);
      const nlohmann::json j = to_json(s);
      write_text_file_atomic(o->views.out_dir + "/study.json", j.dump(2) + "\n");
      if (o->json) {
        std::cout << j.dump(2) << "\n";
        return 0;
      }
      std::printf("%-20s %-8s %-8s %-11s %-8s %-9s %s\n", "view", "size", "shading", "spacing_mm", "ssim", "psnr_db",
                  "frame_s");
      for (const ViewResolutionRow& r : s.rows)
        std::printf("%-20s %-8s %-8s %-11.2f %-8.3f %-9.1f %.2f\n", r.view.c_str(), r.size.c_str(), r.shading.c_str(),
                    r.spacing_mm, r.ssim, r.psnr_db, r.frame_seconds);
      std::printf("views in %s/views; one solve of %.1f s; %.1f s in all\n", o->views.out_dir.c_str(), s.solve_seconds,
                  s.seconds);
      return 0;
    }
    if (pv->parsed()) {
      const PressureVolumeStudy s = pressure_volume_study(load_scene(o->scene), o->pressures);
      if (o->json) {
        std::cout << to_json(s).dump(2) << "\n";
        return 0;
      }
      std::printf("%-14s %-12s %-10s %s\n", "pressure_mmhg", "cavity_ml", "rise_mm", "converged");
      for (const PressurePoint& p : s.curve)
        std::printf("%-14.1f %-12.1f %-10.2f %s\n", p.pressure_mmhg, p.cavity_volume_ml, p.anterior_rise_mm,
                    p.converged ? "yes" : "no");
      std::printf("compliance 5-15 mmHg: %.1f ml/mmHg; V(15)/V(30) = %.2f (patients about 0.67, McDougall 1994; a "
                  "linear wall 0.5)\n",
                  s.compliance_ml_per_mmhg, s.fraction_of_30_at_15);
      return s.all_converged ? 0 : 1;
    }
    if (conv->parsed()) {
      const ConvergenceStudy s = convergence_study(load_scene(o->scene), o->cube_voxels);
      if (o->json) {
        std::cout << to_json(s).dump(2) << "\n";
        return 0;
      }
      std::printf("%-8s %-8s %-10s %-12s %-12s %-12s %-9s %-8s %s\n", "cube", "cube_mm", "rise_mm", "cavity_ml",
                  "wall_mean_mm", "viscera_back", "nodes", "inverted", "converged");
      for (const ConvergenceRow& r : s.rows)
        std::printf("%-8s %-8.1f %-10.2f %-12.1f %-12.2f %-12.2f %-9lld %-8lld %s\n", r.cube.text().c_str(), r.cube_mm,
                    r.anterior_rise_mm, r.cavity_volume_ml, r.mean_wall_displacement_mm, r.viscera_posterior_motion_mm,
                    (long long)r.nodes, (long long)r.inverted, r.converged ? "yes" : "no");
      auto line = [](const char* what, const ObservedOrder& oo) {
        if (oo.monotone) std::printf("%s: observed order %.2f, extrapolated %.2f\n", what, oo.order, oo.extrapolated);
        else
          std::printf("%s: the differences over the three finest sizes change sign or vanish: no order to fit "
                      "(settled within their scatter, or not yet asymptotic: see the change below)\n", what);
      };
      line("rise", s.rise);
      line("cavity", s.volume);
      line("wall mean", s.wall);
      line("viscera back (posterior motion of their anterior half)", s.viscera);
      std::printf("change between the two finest sizes: rise %.1f %%, cavity %.1f %%\n", 100 * s.finest_change_rise,
                  100 * s.finest_change_volume);
      return 0;
    }
    if (lattice->parsed()) {
      if (o->across < 4 || o->across % 2) throw InputError("validate lattice: --cubes must be even and at least 4");
      const LatticeResult r = validate_lattice(o->across);
      if (o->json) std::cout << to_json(r).dump(2) << "\n";
      else
        std::printf("lattice Young's modulus along an axis: %.4f E (expected 1.140 E, %+.2f %%), %d cubes across\n",
                    r.young_ratio_axis, 100.0 * (r.young_ratio_axis / r.expected_axis - 1.0), r.cubes_across);
      return 0;
    }
    if (const auto model = enum_from_name<MaterialModel>(o->lame_model)) o->lame.model = *model;
    o->lame.mean_dilatation = !o->per_tetrahedron;
    if (o->lame.model == MaterialModel::Msd && o->lame.poisson != 0.25)
      throw InputError("validate lame-sphere: --poisson applies to the FEM models; the springs' ν is 1/4");
    const LameResult r = validate_lame_sphere(o->lame);
    if (o->json) std::cout << to_json(r).dump(2) << "\n";
    else {
      std::printf("Lamé sphere a = %g mm, b = %g mm, E = %g kPa, nu = %g, %s, %g mmHg, cubes %g mm, voxels %g mm, %d placements "
                  "(%lld nodes each, %.1f s)\n",
                  o->lame.inner_mm, o->lame.outer_mm, o->lame.young_kpa,
                  o->lame.model == MaterialModel::Msd ? 0.25 : o->lame.poisson, o->lame_model.c_str(),
                  o->lame.pressure_mmhg, o->lame.cube_mm, lame_voxel_mm(o->lame), o->lame.placements, (long long)r.nodes,
                  r.wall_time_s);
      std::printf("  on the true spheres r = a and r = b (the mesh's field there):\n");
      std::printf("  inner: %.4f mm, nominal %.4f (%+.1f %%), model's moduli %.4f (%+.1f %%)\n", r.u_inner_mm,
                  r.u_inner_analytic_mm, 100 * r.rel_error_inner, r.u_inner_lattice_mm, 100 * r.rel_error_inner_lattice);
      std::printf("         placements %.4f … %.4f mm; plain node mean %.4f mm\n", r.u_inner_min_mm, r.u_inner_max_mm,
                  r.u_inner_node_mean_mm);
      std::printf("  outer: %.4f mm, nominal %.4f (%+.1f %%), model's moduli %.4f (%+.1f %%)\n", r.u_outer_mm,
                  r.u_outer_analytic_mm, 100 * r.rel_error_outer, r.u_outer_lattice_mm, 100 * r.rel_error_outer_lattice);
      std::printf("         placements %.4f … %.4f mm; plain node mean %.4f mm\n", r.u_outer_min_mm, r.u_outer_max_mm,
                  r.u_outer_node_mean_mm);
      std::printf("  over the mesh's boundary (nodes up to a cube from the spheres): inner %.4f mm, outer %.4f mm\n",
                  r.u_inner_boundary_mm, r.u_outer_boundary_mm);
    }
    return 0;
  };
}

}  // namespace pneumo::cli
