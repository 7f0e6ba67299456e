#pragma once
// `pneumo bench`: one process measures every stage on every device, the speed–accuracy trade of the solvers and
// their stability limits, and writes one JSON document (and optionally Markdown with an SVG plot beside it).
//
// Sections of the JSON (every one present in a --quick run too, on smaller inputs):
//   machine         CPU model, cores, OpenMP threads, OpenCL devices, GL renderer, load averages before and after
//   bandwidth       STREAM triad measured in this run: natively on 1 and all threads, and on each OpenCL device
//   throughput      per case (phantoms, the real CT) and device: force evaluations, explicit steps, the solve, the
//                   warp and a rendered frame, medians over repetitions with min/max, roofline ratios, peak memory
//   speed_accuracy  solver × cube size × step/tolerance: wall time and the error against a reference solution at
//                   the same material points, the Pareto front, and the presets it implies
//   stability       the largest stable Δt of explicit and Newmark-β by bisection against method.md §6's estimate
//   material_models the springs and the finite elements side by side: Lamé's error, the real CT at each preset,
//                   element updates per second, and the model each preset should use (material_models.h)
//   notes           what was skipped and why, and how to read the figures
#include <string>

#include <nlohmann/json.hpp>

namespace pneumo::bench {

struct BenchOptions {
  bool quick = false;            // the CI smoke run: the small phantom, few repetitions, seconds
  std::string real_ct_scene;     // a scene of the real CT; skipped with a note when it or its CT is missing
  std::string real_ct_fem_scene; // the same CT with finite elements (the material-model rows)
  std::string json_path, markdown_path;   // "" = not written; the plot goes beside the Markdown as .svg
};

/// Runs everything and returns the JSON document (also written where the options say, atomically).
nlohmann::json run_bench(const BenchOptions& options);

}  // namespace pneumo::bench
