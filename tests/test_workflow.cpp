// The cohort workflow (workflow/Snakefile, docs/workflow.md): the shipped
// example config, run by Snakemake from the repository root with 2 cores as a user would, only its output
// folder moved to a scratch folder and the pneumo binary named. Compared: the gathered table holds one row per
// case × setting (the small phantom and the real CT, each at 10 and 15 mmHg), every run finished and converged,
// the rise and cavity are positive and grow with the pressure in each case (a sweep that mixed up its settings
// would not), the figure exists; and a second call finds nothing to do (Snakemake's bookkeeping, what makes a
// cohort resumable).
#include <gtest/gtest.h>

#include <map>
#include <sstream>
#include <vector>

#include "cli_test_support.h"

namespace pneumo {
namespace {

using namespace testing_support;

std::vector<std::map<std::string, std::string>> read_csv(const std::string& path) {
  std::istringstream in(slurp(path));
  std::string line;
  std::vector<std::string> header;
  std::vector<std::map<std::string, std::string>> rows;
  auto split = [](const std::string& s) {   // the table's cells hold no commas or quotes
    std::vector<std::string> cells;
    std::stringstream ss(s);
    for (std::string cell; std::getline(ss, cell, ',');) cells.push_back(cell);
    return cells;
  };
  if (std::getline(in, line)) header = split(line);
  while (std::getline(in, line)) {
    const std::vector<std::string> cells = split(line);
    std::map<std::string, std::string> row;
    for (std::size_t i = 0; i < header.size() && i < cells.size(); ++i) row[header[i]] = cells[i];
    rows.push_back(row);
  }
  return rows;
}

TEST(Workflow, TheExampleCohortGathersOneRowPerCaseAndSetting) {
  ScratchDir tmp;
  const std::string out = tmp.file("cohort");
  const std::string snakemake = "cd " + std::string(PNEUMO_SOURCE_DIR) +
                                " && snakemake -s workflow/Snakefile --cores 2 --config out=" + out +
                                " pneumo=" + PNEUMO_CLI_PATH;
  const CliResult first = run_shell(snakemake);
  ASSERT_EQ(first.code, 0) << first.err;
  const std::vector<std::map<std::string, std::string>> rows = read_csv(out + "/cohort.csv");
  ASSERT_EQ(rows.size(), 4u);
  std::map<std::string, std::map<std::string, double>> rise, cavity;
  for (const auto& r : rows) {
    SCOPED_TRACE(r.at("case") + " " + r.at("setting"));
    EXPECT_EQ(r.at("converged"), "True");
    EXPECT_EQ(r.at("pipeline_complete"), "True");
    rise[r.at("case")][r.at("setting")] = std::stod(r.at("anterior_rise_mm"));
    cavity[r.at("case")][r.at("setting")] = std::stod(r.at("cavity_volume_ml"));
    EXPECT_EQ(std::stod(r.at("pressure_mmhg")), r.at("setting") == "p10_preview" ? 10.0 : 15.0);
  }
  for (const char* c : {"phantom_small", "real_ct"}) {
    SCOPED_TRACE(c);
    EXPECT_GT(rise[c]["p10_preview"], 0.0);
    EXPECT_GT(rise[c]["p15_preview"], rise[c]["p10_preview"]);
    EXPECT_GT(cavity[c]["p15_preview"], cavity[c]["p10_preview"]);
  }
  EXPECT_NE(slurp(out + "/cohort.svg").find("<svg"), std::string::npos);

  const CliResult second = run_shell(snakemake);
  ASSERT_EQ(second.code, 0) << second.err;
  EXPECT_NE((second.out + second.err).find("Nothing to be done"), std::string::npos) << second.err;
}

}  // namespace
}  // namespace pneumo
