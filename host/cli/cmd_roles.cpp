#include <chrono>
#include <cstdio>
#include <optional>

#include "cli/commands.h"
#include "core/atomic_file.h"
#include "core/error.h"
#include "pipeline/scene_stages.h"
#include "report/role_png.h"
#include "roles/roles.h"
#include "scene/scene.h"

namespace pneumo::cli {

namespace {

void print_summary(const Scene& scene, const RoleVolume& rv, double seconds) {
  const Geometry& g = rv.geometry;
  std::printf("roles of %s (source %s) in %.2f s\n", scene.name.empty() ? scene.path.c_str() : scene.name.c_str(),
              enum_name(scene.roles.source), seconds);
  std::printf("  grid %lld x %lld x %lld at %g x %g x %g mm, %s, origin (%.2f, %.2f, %.2f) mm\n",
              (long long)g.dims[0], (long long)g.dims[1], (long long)g.dims[2], g.spacing_mm[0], g.spacing_mm[1],
              g.spacing_mm[2], g.orientation_code().c_str(), g.origin_mm[0], g.origin_mm[1], g.origin_mm[2]);
  std::printf("  padding (voxels, low/high end): i %lld/%lld, j %lld/%lld, k %lld/%lld\n", (long long)rv.pad.lo[0],
              (long long)rv.pad.hi[0], (long long)rv.pad.lo[1], (long long)rv.pad.hi[1], (long long)rv.pad.lo[2],
              (long long)rv.pad.hi[2]);
  std::printf("  %-8s %12s %12s\n", "role", "voxels", "ml");
  const std::array<int64_t, 4> voxels = rv.counts();
  for (Role r : {Role::Wall, Role::Viscera, Role::Fixed, Role::Other})
    std::printf("  %-8s %12lld %12.1f\n", role_name(r), (long long)voxels[std::size_t(r)],
                double(voxels[std::size_t(r)]) * rv.voxel_volume_ml());
}

}  // namespace

Run add_roles(CLI::App& app) {
  auto* cmd = app.add_subcommand("roles", "Assign wall/viscera/fixed/other to every voxel of a scene's CT and summarise (optionally draw) them");
  struct Opts {
    std::string scene, png;
    std::vector<double> at;
  };
  auto o = std::make_shared<Opts>();
  cmd->add_option("scene", o->scene, "The scene .json file")->required();
  cmd->add_option("--png", o->png, "Write axial/coronal/sagittal slices with the roles coloured over the CT");
  cmd->add_option("--at", o->at, "World point (mm, RAS) where the slices cross, as X,Y,Z (default: the grid's centre)")
      ->delimiter(',')
      ->expected(3);
  return [=] {
    const Scene scene = load_scene(o->scene);
    if (!o->png.empty()) check_writable_target(o->png);   // fail before the work, not after
    const auto t0 = std::chrono::steady_clock::now();
    const RoleVolume rv = load_roles(scene);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    print_summary(scene, rv, seconds);
    if (!o->png.empty()) {
      std::optional<Vec3> at;
      if (o->at.size() == 3) at = Vec3(o->at[0], o->at[1], o->at[2]);
      write_roles_png(rv, o->png, at);
      std::printf("  wrote %s\n", o->png.c_str());
    }
    return 0;
  };
}

}  // namespace pneumo::cli
