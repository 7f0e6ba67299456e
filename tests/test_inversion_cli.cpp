// Tetrahedra inverting under extreme load, end to end: the tiny case (tiny_case_support.h)
// made soft (E = 6 kPa, no volume-preserving force) under 12 mmHg turns tetrahedra inside out on
// every solver and device (measured: 8 or 16 of 540 at the first check, 124 or 244 at equilibrium).
// With solver.on_inverted = "stop", `pneumo simulate` and `pneumo run` must stop: exit 1 (pneumo
// stopping on a valid scene), one line on stderr counting the inverted tetrahedra and saying what
// to change, and nothing written (a stopped shape is no result). With "continue" they must finish
// and count them in metrics.json and the summary.
#include <gtest/gtest.h>

#include <filesystem>
#include <regex>
#include <set>
#include <string>
#include <tuple>

#include "cli_test_support.h"
#include "opencl_test_support.h"
#include "springs_support.h"
#include "tiny_case_support.h"

namespace pneumo {
namespace {

using namespace testing_support;
using json = nlohmann::json;
namespace fs = std::filesystem;

std::string inverting_case(const ScratchDir& d, const std::string& method, const std::string& on_inverted) {
  json s = tiny_case_scene_json();
  s["material"] = springs_material_json();   // a soft spring lattice inverts; the elements resist it
  s["material"]["young_kpa"] = 6;
  s["material"]["volume_stiffness_kpa"] = 0;
  s["solver"] = {{"method", method}, {"on_inverted", on_inverted}};
  return write_tiny_case(d, s);
}

/// The number in "N inverted tetrahedra" of a summary line, -1 when it is not there.
long long inverted_in_summary(const std::string& line) {
  std::smatch m;
  return std::regex_search(line, m, std::regex("([0-9]+) inverted tetrahedra")) ? std::stoll(m[1]) : -1;
}

using MethodOnDevice = std::tuple<std::string, std::string>;   // solver.method; --device

class InvertedTetrahedraCli : public ::testing::TestWithParam<MethodOnDevice> {};

TEST_P(InvertedTetrahedraCli, StopExitsOneWithTheCountAndAdviceAndWritesNothing) {
  const auto& [method, device] = GetParam();
  for (const char* command : {"simulate", "run"}) {
    SCOPED_TRACE(command);
    ScratchDir d;
    const std::string scene = inverting_case(d, method, "stop");
    const std::set<std::string> before = tree(d.path());
    const CliResult r =
        run_pneumo(std::string("-q ") + command + " " + scene + " --out " + d.file("out") + " --device " + device);
    EXPECT_EQ(r.code, 1) << r.err;
    ASSERT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_TRUE(std::regex_search(r.err, std::regex(method + " stopped at step [0-9]+ .*: [1-9][0-9]* of 540 "
                                                             "tetrahedra turned inside out")))
        << r.err;
    for (const char* words : {"solver.on_inverted", "load.pressure_mmhg", "material.young_kpa"})
      EXPECT_NE(r.err.find(words), std::string::npos) << r.err;
    EXPECT_TRUE(r.out.empty()) << r.out;
    EXPECT_EQ(tree(d.path()), before) << "something was written";
  }
}

TEST_P(InvertedTetrahedraCli, ContinueFinishesAndCountsThemInMetrics) {
  const auto& [method, device] = GetParam();
  ScratchDir d;
  const std::string scene = inverting_case(d, method, "continue");
  const CliResult r = run_pneumo("-q simulate " + scene + " --out " + d.file("out") + " --device " + device);
  ASSERT_EQ(r.code, 0) << r.err;
  const json m = json::parse(slurp(d.file("out/metrics.json")));
  EXPECT_TRUE(m["converged"].get<bool>());
  EXPECT_GT(m["inverted_tetrahedra"].get<int64_t>(), 0);
  EXPECT_EQ(inverted_in_summary(r.out), m["inverted_tetrahedra"].get<int64_t>()) << r.out;
}

INSTANTIATE_TEST_SUITE_P(EverySolver, InvertedTetrahedraCli,
                         ::testing::Combine(::testing::Values("static", "explicit", "newmark", "kitasaka2004"),
                                            ::testing::ValuesIn(cpu_and_opencl_device_specs())),
                         [](const ::testing::TestParamInfo<MethodOnDevice>& info) {
                           return std::get<0>(info.param) + "_" + spec_name(std::get<1>(info.param));
                         });

TEST(InvertedTetrahedraRun, ContinueRunsTheWholeCaseAndReportsTheCount) {
  // Compared: `pneumo run` with "continue": a finished run (report.html, metrics.json complete) whose
  // metrics.json and summary line give the same count, > 0.
  ScratchDir d;
  const std::string scene = inverting_case(d, "static", "continue");
  const CliResult r = run_pneumo("-q run " + scene + " --out " + d.file("out"));
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(fs::exists(d.file("out/report.html")));
  const json m = json::parse(slurp(d.file("out/metrics.json")));
  EXPECT_TRUE(m["pipeline_complete"].get<bool>());
  EXPECT_GT(m["inverted_tetrahedra"].get<int64_t>(), 0);
  EXPECT_EQ(inverted_in_summary(r.out), m["inverted_tetrahedra"].get<int64_t>()) << r.out;
}

}  // namespace
}  // namespace pneumo
