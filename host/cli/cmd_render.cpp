#include <filesystem>
#include <memory>

#include "cli/commands.h"
#include "cli/gl_backend_option.h"
#include "core/atomic_file.h"
#include "core/error.h"
#include "core/output_lock.h"
#include "core/owned_folder.h"
#include "pipeline/render_scene.h"
#include "pipeline/warp_stage.h"

namespace pneumo::cli {

Run add_render(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "render", "Render the laparoscope's views, ports, fly-throughs and exterior views of a scene into --out");
  struct Opts { std::string scene, out, backend = "auto"; bool cpu = false, force = false; };
  auto o = std::make_shared<Opts>();
  cmd->add_option("scene", o->scene, "Scene .json")->required();
  cmd->add_option("--out", o->out,
                  "Output folder; renders its deformed_ct.nii.gz (from simulate) when present, else the scene's CT")
      ->required();
  add_gl_backend_option(cmd, o->backend, "the views");
  cmd->add_flag("--cpu", o->cpu, "Render with the CPU reference ray caster instead of OpenGL (slow)");
  cmd->add_flag("--force", o->force, "Replace the views of an earlier render in --out");
  return [=] {
    const Scene scene = load_scene(o->scene);
    const OutputFolderLock lock(o->out);   // one pneumo at a time in --out (core/output_lock.h)
    // A finished render (or run) in --out: its views are what its report shows; replacing them with
    // other settings would leave a report of images it did not make. As simulate and warp refuse.
    if (!o->force && std::filesystem::exists(std::filesystem::path(o->out) / "render.json"))
      throw InputError(o->out + ": already holds rendered views (render.json); use --force to replace them");
    for (const char* own : {"views", "flythrough"}) check_owned_or_absent(std::filesystem::path(o->out) / own);
    RenderOptions opt;
    opt.out_dir = o->out;
    opt.backend = parse_gl_backend(o->backend);
    opt.cpu_reference = o->cpu;
    // Checked now; the render writes into it only once the volumes are read and every pose is valid
    // (the lock above created it if missing and removes it again if nothing was written).
    check_creatable_folder(o->out);
    // After simulate and warp into the same folder, ports travel with the skin through the solved shape.
    std::unique_ptr<DeformedMesh> deformed;
    std::unique_ptr<PointMap> point_map;
    if (std::filesystem::exists(std::filesystem::path(o->out) / "deformed_ct.nii.gz") &&
        std::filesystem::exists(std::filesystem::path(o->out) / "deformation.bin")) {
      deformed = std::make_unique<DeformedMesh>(load_deformed_mesh(scene, o->out));
      point_map = std::make_unique<PointMap>(deformed->point_map());
      opt.map_point = deformed_point_fn(*point_map);
    }
    const RenderRun run = render_scene(scene, opt);
    const auto& rj = run.report["render"];
    std::printf("render: %d views and %d fly-through frames from %s (%s%s); results in %s\n", run.views, run.frames,
                run.deformed ? "the deformed CT" : "the original CT", rj["renderer"].get<std::string>().c_str(),
                rj.contains("gl_renderer") ? (", " + rj["gl_renderer"].get<std::string>()).c_str() : "",
                o->out.c_str());
    return 0;
  };
}

}  // namespace pneumo::cli
