#pragma once
// `pneumo bench --pipeline`: what a user waits for, from a CT file to the first laparoscope view. The phantom
// is written to disk as a case (CT, labels, scene), and `pneumo run` is started as a new process on it for each
// preset and device, as a user starts it: the wall time from the start to the first view PNG on disk and to
// the end, and each stage's seconds from the run's metrics.json, medians over repetitions with their spread, and
// how much CPU other processes took meanwhile. Nimura 2015 (about 150 min) and Kitasaka 2004 (75 min) for their
// deformation alone are the anchors.
#include <string>

#include <nlohmann/json.hpp>

namespace pneumo::bench {

struct PipelineBenchOptions {
  bool quick = false;   // the smoke run: the small phantom, preview, the CPU, one repetition
  std::string json_path, markdown_path;   // "" = not written
};

/// Runs the cases and returns the JSON document (also written where the options say, atomically).
nlohmann::json run_pipeline_bench(const PipelineBenchOptions& options);

/// The document as Markdown: one table per case, a row per preset and device.
std::string pipeline_bench_markdown(const nlohmann::json& doc);

}  // namespace pneumo::bench
