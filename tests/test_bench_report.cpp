// The benchmark's Markdown (bench/suite/bench_report.cpp) from a stored full run: the JSON of
// bench/results/2026-12-05-bench.json renders with today's report code, and a real-CT row the run left out
// (a model and solver that did not converge at a coarser preset, material_models.cpp) reads as such, with
// dashes where it measured nothing. Compared: the rendered text contains every section title, the
// skipped row's reason and dashes for its nodes and time; no exception (a row missing a key the report
// reads would throw).
#include <gtest/gtest.h>

#include <fstream>

#include <nlohmann/json.hpp>

#include "suite/bench_report.h"

namespace {

TEST(BenchReport, TheStoredFullRunRendersAndASkippedRowReadsAsSuch) {
  std::ifstream in(std::string(PNEUMO_SOURCE_DIR) + "/bench/results/2026-12-05-bench.json");
  ASSERT_TRUE(in) << "the stored run is part of the repository";
  nlohmann::json doc = nlohmann::json::parse(in);
  nlohmann::json& rows = doc["material_models"]["real_ct"];
  ASSERT_GE(rows.size(), 9u);
  // What material_models.cpp writes for a run it skips.
  rows[8] = {{"model", "fem-neohookean"}, {"solver", "static"}, {"cube_voxels", 2}, {"cube_mm", 6.0},
             {"nodes", nullptr}, {"wall_s", nullptr}, {"converged", false}, {"preset", "accurate"},
             {"stop_reason", "not run: it did not converge at the coarser balanced preset"}};
  const std::string md = pneumo::bench::bench_markdown(doc, "bench.svg");
  for (const char* title : {"## Machine and load", "## Speed against accuracy", "## Stability map", "## Material models"})
    EXPECT_NE(md.find(title), std::string::npos) << title;
  EXPECT_NE(md.find("| accurate | fem-neohookean | static | 6 mm | – | – | – | – | – | – | – | – | not run: it did not "
                    "converge at the coarser balanced preset |"),
            std::string::npos)
      << md.substr(md.find("The real CT at each preset"), 3000);
}

}  // namespace
