// `pneumo bench`: the one-process benchmark (code in bench/suite; see bench_suite.h for what it measures).
#include <cstdio>

#include "cli/commands.h"
#include "suite/bench_suite.h"

namespace pneumo::cli {

Run add_bench(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "bench", "Measure every stage on every device, the solvers' speed against accuracy and their stable time "
               "steps (a full run takes about 15-20 minutes on 2 cores; --quick is the seconds-long smoke run)");
  auto o = std::make_shared<bench::BenchOptions>();
  o->real_ct_scene = "scenes/totalseg_example.json";
  cmd->add_flag("--quick", o->quick, "Smoke run: the small phantom, few repetitions (checks the harness, not the machine)");
  cmd->add_option("--json", o->json_path, "Write the results as JSON");
  cmd->add_option("--markdown", o->markdown_path, "Write the results as Markdown, and the speed-accuracy plot beside it (.svg)");
  cmd->add_option("--real-ct", o->real_ct_scene, "Scene of the real CT (skipped with a note when it or its CT is missing)")
      ->capture_default_str();
  return [o] {
    const nlohmann::json doc = bench::run_bench(*o);
    if (o->json_path.empty() && o->markdown_path.empty()) std::printf("%s\n", doc.dump(2).c_str());
    else std::fprintf(stderr, "[bench] done in %.0f s\n", doc["wall_time_s"].get<double>());
    return 0;
  };
}

}  // namespace pneumo::cli
