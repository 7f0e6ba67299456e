#include <chrono>
#include <filesystem>
#include <iostream>

#include "cli/commands.h"
#include "core/error.h"
#include "io/volume_info.h"
#include "phantom/phantom.h"

namespace pneumo::cli {

Run add_phantom(CLI::App& app) {
  auto* cmd = app.add_subcommand("phantom", "Write the embedded default case: a synthetic abdomen CT, its labels and a scene");
  struct Opts { std::string out, size = "small"; bool force = false; };
  auto o = std::make_shared<Opts>();
  cmd->add_option("--out", o->out, "Output folder (created if needed)")->required();
  cmd->add_option("--size", o->size, "small (96^3 at 4 mm), medium (256x256x200 at 1.5 mm), large (512x512x400 at 0.75 mm)")
      ->capture_default_str();
  cmd->add_flag("--force", o->force, "Overwrite a case already in --out");
  return [=] {
    const PhantomSize size = parse_phantom_size(o->size);
    namespace fs = std::filesystem;
    for (const char* f : {"ct.nii.gz", "labels.nii.gz", "scene.json"})
      if (fs::exists(fs::path(o->out) / f) && !o->force)
        throw InputError(o->out + ": already holds " + f + "; use --force to overwrite");
    const auto t0 = std::chrono::steady_clock::now();
    const Phantom p = make_phantom(size);
    write_phantom_case(p, size, o->out);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

    const Geometry& g = p.ct.geometry();
    const VolumeInfo labels = describe_volume(p.labels);
    std::printf("phantom %s: %lld x %lld x %lld voxels at %g x %g x %g mm, %s, written to %s in %.1f s\n",
                o->size.c_str(), (long long)g.dims[0], (long long)g.dims[1], (long long)g.dims[2], g.spacing_mm[0],
                g.spacing_mm[1], g.spacing_mm[2], g.orientation_code().c_str(), o->out.c_str(), seconds);
    std::printf("  %5s  %-24s %-8s %8s %10s\n", "id", "structure", "role", "HU", "volume ml");
    for (const auto& l : phantom_labels()) {
      const auto it = labels.label_voxels.find(l.id);
      const double ml = it == labels.label_voxels.end() ? 0.0 : double(it->second) * labels.voxel_volume_ml;
      std::printf("  %5d  %-24s %-8s %8.0f %10.1f\n", l.id, l.name.c_str(), role_name(l.role), l.hu, ml);
    }
    return 0;
  };
}

}  // namespace pneumo::cli
