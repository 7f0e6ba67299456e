// `pneumo bench`: the one-process benchmark (code in bench/suite; see bench_suite.h for what it measures).
#include <cstdio>

#include "cli/commands.h"
#include "suite/bench_suite.h"
#include "suite/peer_warp.h"
#include "suite/pipeline_bench.h"

namespace pneumo::cli {

Run add_bench(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "bench", "Measure every stage on every device, the solvers' speed against accuracy and their stable time "
               "steps (a full run takes up to an hour on 2 cores; --quick is the seconds-long smoke run)");
  auto o = std::make_shared<bench::BenchOptions>();
  o->real_ct_scene = "scenes/totalseg_example_springs.json";
  o->real_ct_fem_scene = "scenes/totalseg_example.json";
  cmd->add_flag("--quick", o->quick, "Smoke run: the small phantom, few repetitions (checks the harness, not the machine)");
  cmd->add_option("--json", o->json_path, "Write the results as JSON");
  cmd->add_option("--markdown", o->markdown_path, "Write the results as Markdown, and the speed-accuracy plot beside it (.svg)");
  cmd->add_option("--real-ct", o->real_ct_scene, "Scene of the real CT (skipped with a note when it or its CT is missing)")
      ->capture_default_str();
  cmd->add_option("--real-ct-fem", o->real_ct_fem_scene,
                  "The real CT's scene with finite elements, beside the springs' in the material-model rows")
      ->capture_default_str();
  auto pipeline = std::make_shared<bool>(false);
  cmd->add_flag("--pipeline", *pipeline,
                "Instead of the suite: a CT file to the first view, `pneumo run` per preset and device on the medium and "
                "large phantoms, stage by stage (--quick: the small phantom, preview, the CPU)");
  auto peer = std::make_shared<bench::PeerWarpOptions>();
  cmd->add_option("--peer-warp", peer->data_dir,
                  "Instead of the suite: warp the peers' phantom (DIR/phantom.mhd from ../shared/peers/phantom.py) "
                  "through their mesh and lift (vtk_tetwarp.py) on the CPU and OpenCL, for bench/peers/compare_warp.sh");
  cmd->add_option("--peer-out", peer->out_dir, "Where --peer-warp writes (default DIR/pneumo)");
  cmd->add_option("--node-step", peer->node_step, "--peer-warp: voxels between mesh nodes (vtk_tetwarp.py --node-step)")
      ->capture_default_str();
  cmd->add_option("--amp", peer->amp_mm, "--peer-warp: the lift's amplitude, mm (vtk_tetwarp.py --amp)")
      ->capture_default_str();
  cmd->add_option("--peer-device", peer->devices, "--peer-warp: the devices to warp on (repeat the flag)")
      ->capture_default_str();
  cmd->add_option("--repeats", peer->repeats, "--peer-warp: warps per device; the median time is reported")
      ->check(CLI::Range(1, 100))
      ->capture_default_str();
  cmd->add_flag("--no-field", peer->skip_field,
                "--peer-warp: skip disp_pneumo.mhd (the dense field through PointMap that compare_warp.sh hands ITK)");
  return [o, peer, pipeline] {
    if (*pipeline) {
      bench::PipelineBenchOptions p;
      p.quick = o->quick;
      p.json_path = o->json_path;
      p.markdown_path = o->markdown_path;
      const nlohmann::json doc = bench::run_pipeline_bench(p);
      if (o->json_path.empty() && o->markdown_path.empty()) std::printf("%s", bench::pipeline_bench_markdown(doc).c_str());
      else std::fprintf(stderr, "[bench] pipeline done in %.0f s\n", doc["wall_time_s"].get<double>());
      return 0;
    }
    if (!peer->data_dir.empty()) {
      const nlohmann::json doc = bench::run_peer_warp(*peer);
      std::printf("%s\n", doc.dump(2).c_str());
      return 0;
    }
    const nlohmann::json doc = bench::run_bench(*o);
    if (o->json_path.empty() && o->markdown_path.empty()) std::printf("%s\n", doc.dump(2).c_str());
    else std::fprintf(stderr, "[bench] done in %.0f s\n", doc["wall_time_s"].get<double>());
    return 0;
  };
}

}  // namespace pneumo::cli
