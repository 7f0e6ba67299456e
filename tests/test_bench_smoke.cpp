// `pneumo bench --quick`: the CI smoke run of the benchmark harness (bench/suite). What is checked: the command
// succeeds, the JSON has every section the full run has (machine, bandwidth, throughput with each stage on each
// device, speed_accuracy with its runs, Pareto marks and presets, stability), every number in it is finite, and
// the Markdown and its plot are written. Nothing asserts on a time: the machine is shared, and the full run's
// numbers are read by people (bench/results), not tests.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <functional>
#include <set>

#include <nlohmann/json.hpp>

#include "cli_test_support.h"

using namespace pneumo::testing_support;
using json = nlohmann::json;

namespace {

/// Paths of the numbers that are not finite ("" when all are).
void non_finite(const json& j, const std::string& path, std::vector<std::string>& bad) {
  if (j.is_number_float() && !std::isfinite(j.get<double>())) bad.push_back(path);
  if (j.is_object())
    for (auto it = j.begin(); it != j.end(); ++it) non_finite(*it, path + "." + it.key(), bad);
  if (j.is_array())
    for (std::size_t i = 0; i < j.size(); ++i) non_finite(j[i], path + "[" + std::to_string(i) + "]", bad);
}

}  // namespace

TEST(BenchSmoke, QuickRunWritesEverySectionWithFiniteNumbers) {
  ScratchDir tmp;
  const std::string js = tmp.file("bench.json"), md = tmp.file("bench.md");
  const CliResult r = run_pneumo("bench --quick --json " + js + " --markdown " + md);
  ASSERT_EQ(r.code, 0) << r.err;
  const json doc = json::parse(slurp(js));

  for (const char* key : {"schema", "machine", "bandwidth", "throughput", "speed_accuracy", "stability",
                          "material_models", "notes", "wall_time_s"})
    EXPECT_TRUE(doc.contains(key)) << key;
  std::vector<std::string> bad;
  non_finite(doc, "", bad);
  EXPECT_TRUE(bad.empty()) << "not finite: " << (bad.empty() ? "" : bad.front());

  EXPECT_FALSE(doc["machine"]["cpu_model"].get<std::string>().empty());
  ASSERT_GE(doc["bandwidth"].size(), 1u);
  for (const auto& [name, bw] : doc["bandwidth"].items()) EXPECT_GT(bw["median_gb_s"].get<double>(), 0) << name;

  // Throughput: the small phantom on every device, each stage with its rates and roofline ratios.
  ASSERT_EQ(doc["throughput"].size(), 1u);
  const json& c = doc["throughput"][0];
  EXPECT_EQ(c["case"], "small");
  EXPECT_GT(c["peak_rss_mib"].get<double>(), 0);
  ASSERT_GE(c["devices"].size(), 1u);
  for (const json& d : c["devices"]) {
    SCOPED_TRACE(d["device"].get<std::string>());
    ASSERT_FALSE(d.contains("error")) << d["error"];
    EXPECT_GT(d["forces"]["force_evals_per_s"]["median"].get<double>(), 0);
    EXPECT_GT(d["forces"]["node_updates_per_s"]["median"].get<double>(), 0);
    EXPECT_GT(d["forces"]["roofline"]["fraction"].get<double>(), 0);
    EXPECT_GT(d["explicit_step"]["node_updates_per_s"]["median"].get<double>(), 0);
    EXPECT_GT(d["warp"]["voxels_per_s"]["median"].get<double>(), 0);
    EXPECT_GT(d["warp"]["roofline"]["fraction"].get<double>(), 0);
    EXPECT_GT(d["solve"]["seconds"]["median"].get<double>(), 0);
    EXPECT_GT(d["end_to_end_s"]["median"].get<double>(), 0);
    const json& f = d["forces"]["force_evals_per_s"];
    EXPECT_LE(f["min"].get<double>(), f["median"].get<double>());
    EXPECT_LE(f["median"].get<double>(), f["max"].get<double>());
  }
  EXPECT_TRUE(c["render"].contains("cpu_reference"));

  // Speed against accuracy: every solver ran without diverging and reached an error figure against the reference,
  // or met the harness's wall-clock cap (5 s per run with --quick: a sanitizer build runs 3-10x slower, and a test
  // must not fail on time); the fastest, the static solver, always gets a figure; a front exists.
  const json& sa = doc["speed_accuracy"];
  std::set<std::string> solvers;   // those with at least one run that reached an error figure or the time cap
  int on_front = 0;
  bool has_static_figure = false;
  for (const json& run : sa["runs"]) {
    EXPECT_TRUE(run["error"].is_null()) << run.dump();
    if (run["timed_out"].get<bool>()) solvers.insert(run["solver"].get<std::string>());
    if (run["rms_error_mm"].is_number()) {
      solvers.insert(run["solver"].get<std::string>());
      if (run["solver"] == "static") has_static_figure = true;
      EXPECT_GE(run["rms_error_mm"].get<double>(), 0);
      EXPECT_TRUE(run["warp_mad_hu"].is_number());
      EXPECT_GT(run["skin"]["compared_points"].get<int>(), 0);
      EXPECT_GT(run["cavity"]["compared_points"].get<int>(), 0);
    }
    on_front += run["pareto"].get<bool>();
  }
  EXPECT_EQ(solvers, (std::set<std::string>{"static", "explicit", "newmark", "kitasaka2004"}));
  EXPECT_TRUE(has_static_figure);
  EXPECT_GE(on_front, 1);
  EXPECT_EQ(sa["implied_presets"].size(), 3u);
  EXPECT_EQ(sa["scene_presets"].size(), 3u);

  // Stability: explicit and Newmark, each with a stable step at or above a positive estimate's scale.
  ASSERT_GE(doc["stability"]["rows"].size(), 2u);
  for (const json& row : doc["stability"]["rows"]) {
    EXPECT_GT(row["dt_estimate_ms"].get<double>(), 0);
    EXPECT_GT(row["dt_stable_ms"].get<double>(), 0);
    EXPECT_GT(row["dt_unstable_ms"].get<double>(), row["dt_stable_ms"].get<double>());
  }

  // Material models: the springs and both laws on Lamé's sphere within the closed form's reach at 10 mm
  // cubes (the FEM tests hold them tighter), every FEM law on every OpenCL device, and element rates.
  const json& mm = doc["material_models"];
  ASSERT_GE(mm["lame"].size(), 3u);
  for (const json& row : mm["lame"]) {
    EXPECT_LT(std::abs(row["rel_error_inner"].get<double>()), 0.1) << row.dump();
    EXPECT_LT(std::abs(row["rel_error_outer"].get<double>()), 0.1) << row.dump();
  }
  ASSERT_EQ(mm["throughput"]["rows"].size(), c["devices"].size());   // every device the throughput measured
  for (const json& row : mm["throughput"]["rows"]) EXPECT_GT(row["evaluate_element_updates_per_s"].get<double>(), 0);
  EXPECT_EQ(mm["choice"].size(), 3u);
  for (const json& c : mm["choice"]) {   // per preset: the solver it takes for each model (scene_presets.h)
    ASSERT_EQ(c["models"].size(), 2u) << c.dump();
    EXPECT_EQ(c["models"][1]["model"], "fem-neohookean");
    EXPECT_EQ(c["models"][1]["preset_solver"], "newton");
    // The model to pick needs the real CT, which --quick leaves out: none, and the default named.
    EXPECT_TRUE(c["model_pick"]["model"].is_null()) << c.dump();
    EXPECT_EQ(c["model_pick"]["default_model"], "fem-neohookean");
  }

  EXPECT_NE(slurp(md).find("## Speed against accuracy"), std::string::npos);
  EXPECT_NE(slurp(md).find("## Material models"), std::string::npos);
  EXPECT_NE(slurp(tmp.file("bench.svg")).find("<svg"), std::string::npos);
}
