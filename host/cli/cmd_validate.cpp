#include <iostream>

#include "cli/commands.h"
#include "core/error.h"
#include "validate/validate.h"

namespace pneumo::cli {

Run add_validate(CLI::App& app) {
  auto* cmd = app.add_subcommand("validate", "Check the physics against closed-form truths on this machine");
  cmd->require_subcommand(1);
  struct Opts { bool json = false; int across = 6; LameOptions lame; };
  auto o = std::make_shared<Opts>();
  auto* lattice = cmd->add_subcommand("lattice", "Effective Young's modulus of the cube lattice along an axis (method.md §4: 1.140·E)");
  lattice->add_option("--cubes", o->across, "Cubes across the block (even, >= 4)")->capture_default_str();
  lattice->add_flag("--json", o->json, "Print JSON (key young_ratio_axis)");
  auto* lame = cmd->add_subcommand("lame-sphere", "Hollow sphere under internal pressure against Lamé's solution (method.md §10)");
  lame->add_option("--cube-mm", o->lame.cube_mm, "Cube size in mm")->capture_default_str()->check(CLI::Range(1.0, 50.0));
  lame->add_option("--placements", o->lame.placements, "Positions of the sphere's centre relative to the lattice, averaged")
      ->capture_default_str()->check(CLI::Range(1, 64));
  lame->add_flag("--json", o->json, "Print JSON (u_inner_mm, u_inner_analytic_mm, rel_error_inner, ...)");
  return [=] {
    if (lattice->parsed()) {
      if (o->across < 4 || o->across % 2) throw InputError("validate lattice: --cubes must be even and at least 4");
      const LatticeResult r = validate_lattice(o->across);
      if (o->json) std::cout << to_json(r).dump(2) << "\n";
      else
        std::printf("lattice Young's modulus along an axis: %.4f E (expected 1.140 E, %+.2f %%), %d cubes across\n",
                    r.young_ratio_axis, 100.0 * (r.young_ratio_axis / r.expected_axis - 1.0), r.cubes_across);
      return 0;
    }
    const LameResult r = validate_lame_sphere(o->lame);
    if (o->json) std::cout << to_json(r).dump(2) << "\n";
    else {
      std::printf("Lamé sphere a = %g mm, b = %g mm, E = %g kPa, %g mmHg, cubes %g mm, %d placements "
                  "(%lld nodes each, %.1f s)\n",
                  o->lame.inner_mm, o->lame.outer_mm, o->lame.young_kpa, o->lame.pressure_mmhg, o->lame.cube_mm,
                  o->lame.placements, (long long)r.nodes, r.wall_time_s);
      std::printf("  inner: %.4f mm, nominal %.4f (%+.1f %%), lattice moduli %.4f (%+.1f %%)\n", r.u_inner_mm,
                  r.u_inner_analytic_mm, 100 * r.rel_error_inner, r.u_inner_lattice_mm, 100 * r.rel_error_inner_lattice);
      std::printf("         placements %.4f … %.4f mm; plain node mean %.4f mm\n", r.u_inner_min_mm, r.u_inner_max_mm,
                  r.u_inner_node_mean_mm);
      std::printf("  outer: %.4f mm, nominal %.4f (%+.1f %%), lattice moduli %.4f (%+.1f %%)\n", r.u_outer_mm,
                  r.u_outer_analytic_mm, 100 * r.rel_error_outer, r.u_outer_lattice_mm, 100 * r.rel_error_outer_lattice);
      std::printf("         placements %.4f … %.4f mm; plain node mean %.4f mm\n", r.u_outer_min_mm, r.u_outer_max_mm,
                  r.u_outer_node_mean_mm);
    }
    return 0;
  };
}

}  // namespace pneumo::cli
