// `pneumo bench --pipeline --quick` (bench/suite/pipeline_bench.h): the smoke run starts `pneumo run` as a new
// process on the small phantom's files and reports what a user waits for. Compared against what the fields mean,
// not against times: one case, one row (preview on the CPU) whose run completed, every stage of metrics.json
// present, the first view on disk before the run's end, the stages within the whole, the anchors named, the
// Markdown's table, and the scratch folder gone.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include <nlohmann/json.hpp>

#include "cli_test_support.h"
#include "io_test_support.h"

namespace pneumo {
namespace {

using namespace testing_support;
using json = nlohmann::json;

std::set<std::string> scratch_folders() {
  std::set<std::string> out;
  for (const auto& e : std::filesystem::directory_iterator(std::filesystem::temp_directory_path()))
    if (e.path().filename().string().rfind("pneumo_pipeline_bench_", 0) == 0) out.insert(e.path().string());
  return out;
}

TEST(BenchPipeline, QuickRunTimesEveryStageFromTheCtFileToTheFirstView) {
  ScratchDir d;
  const std::set<std::string> before = scratch_folders();
  const CliResult r = run_pneumo("bench --pipeline --quick --json " + d.file("p.json") + " --markdown " + d.file("p.md"));
  ASSERT_EQ(r.code, 0) << r.err;
  const json doc = json::parse(slurp(d.file("p.json")));
  ASSERT_EQ(doc["cases"].size(), 1u);
  const json& c = doc["cases"][0];
  EXPECT_EQ(c["case"], "small phantom");
  ASSERT_EQ(c["rows"].size(), 1u);
  const json& row = c["rows"][0];
  EXPECT_EQ(row["preset"], "preview");
  EXPECT_EQ(row["device"], "cpu");
  ASSERT_EQ(row["completed"], 1) << row.dump();
  EXPECT_TRUE(row["errors"].empty()) << row.dump();
  const double wall = row["wall_s"]["median"], first = row["first_view_s"]["median"];
  EXPECT_GT(first, 0.0);
  EXPECT_LE(first, wall);
  double stages = 0.0;
  for (const char* s : {"roles", "mesh", "solve", "warp", "render", "report"}) {
    ASSERT_TRUE(row["stage_s"].contains(s)) << s;
    stages += row["stage_s"][s]["median"].get<double>();
  }
  EXPECT_GT(row["stage_s"]["solve"]["median"].get<double>(), 0.0);
  EXPECT_LE(stages, wall);   // the stages run inside the process the wall time measures
  EXPECT_EQ(doc["anchors"].size(), 2u);
  const std::string md = slurp(d.file("p.md"));
  EXPECT_NE(md.find("| preset | device | first view | total |"), std::string::npos) << md;
  EXPECT_NE(md.find("Nimura 2015"), std::string::npos);
  EXPECT_EQ(scratch_folders(), before) << "the run left its scratch folder";
}

}  // namespace
}  // namespace pneumo
