// Hostile input end to end: a tiny case (tiny_case_support.h) with one piece spoiled at a
// time (a truncated or corrupt volume, an absurd header, NaN or Inf voxels, labels off the CT's grid, a
// mapping for another label map, scene keys of the wrong type or unit, missing or unwritable paths,
// roles that leave nothing to move or a wall unanchored, a load that turns tetrahedra inside out with
// solver.on_inverted = "stop"), run through each command that reads that piece: `pneumo simulate`,
// `run`, `render` and `warp` (warp into the folder of the unspoiled case's simulation). Compared, for
// each row and command: the exit code (2 = bad input; 1 for a run that diverges or stops, which is
// pneumo stopping, with advice, on a scene that was valid), stderr is exactly one line holding the
// expected words (the file or key and what to change), stdout holds nothing, and nothing was written:
// the folder holds exactly the files it held before the command, and no output folder appeared. The
// unspoiled case must succeed through every command (the control rows), so every refusal is the
// spoiled piece's doing. A forced `run` over an earlier run's results with a spoiled input must leave
// those results byte for byte.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <functional>
#include <limits>
#include <map>
#include <ostream>
#include <set>
#include <stdexcept>

#include "cli_test_support.h"
#include "springs_support.h"
#include "tiny_case_support.h"

namespace pneumo {
namespace {

using namespace testing_support;
using json = nlohmann::json;

/// The tiny case with the CT written as MetaImage (ct.mha), its header passed through `edit`.
std::string with_mha_ct(const ScratchDir& d, const std::function<std::string(std::string)>& edit) {
  json s = tiny_case_scene_json();
  s["inputs"]["ct"] = "ct.mha";
  const std::string scene = write_tiny_case(d, s);
  write_volume(tiny_case_ct(), d.file("ct.mha"));
  std::string bytes = read_bytes(d.file("ct.mha"));
  const std::size_t end = bytes.find("ElementDataFile = LOCAL\n") + std::strlen("ElementDataFile = LOCAL\n");
  write_bytes(d.file("ct.mha"), edit(bytes.substr(0, end)) + bytes.substr(end));
  return scene;
}

/// The header with the line "KEY = ..." replaced by "KEY = value" (the line must be there).
std::string replace_line(const std::string& header, const std::string& key, const std::string& value) {
  const std::size_t at = header.find(key + " = ");
  EXPECT_TRUE(at == 0 || (at != std::string::npos && header[at - 1] == '\n')) << key << " not in " << header;
  if (at == std::string::npos) return header;
  return header.substr(0, at) + key + " = " + value + header.substr(header.find('\n', at));
}

/// The tiny case with one CT voxel replaced.
std::string with_ct_voxel(const ScratchDir& d, float value) {
  Volume ct = tiny_case_ct();
  ct.data<float>()[ct.geometry().linear_index(5, 6, 4)] = value;
  return write_tiny_case(d, tiny_case_scene_json(), ct);
}

/// The tiny case with one scene key changed (a JSON pointer) or removed (value discarded).
std::string with_scene(const ScratchDir& d, const std::string& pointer, const json& value) {
  json s = tiny_case_scene_json();
  if (value.is_discarded()) s.erase(json::json_pointer(pointer).back());
  else s[json::json_pointer(pointer)] = value;
  return write_tiny_case(d, s);
}

/// The commands a row goes through: each reads the spoiled piece. Render builds no roles or mesh;
/// warp needs the case's own simulation in --out; only simulate and run solve; only warp and run
/// mark the cavity in the labels.
const std::vector<std::string> kEveryCommand = {"simulate", "run", "render", "warp"};
const std::vector<std::string> kRolesCommands = {"simulate", "run", "warp"};
const std::vector<std::string> kMeshCommands = {"simulate", "run"};
const std::vector<std::string> kFolderCommands = {"simulate", "run", "render"};

struct Row {
  std::string name;
  std::function<std::string(const ScratchDir&)> make;   // writes the case, returns the scene path
  std::vector<std::string> expected;                     // substrings of the one error line
  int code = 2;
  std::string out = "out";                               // the --out folder, relative to the case
  std::vector<std::string> commands = kEveryCommand;
};

std::vector<Row> rows() {
  using D = const ScratchDir&;
  const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
  return {
      {"ct_truncated_nifti_gz",
       [](D d) {
         const std::string scene = write_tiny_case(d);
         const std::string bytes = read_bytes(d.file("ct.nii.gz"));
         write_bytes(d.file("ct.nii.gz"), bytes.substr(0, bytes.size() / 2));
         return scene;
       },
       // Half the file: the header's own gzip member is whole (io/gzip_members.h), the voxels are not.
       {"ct.nii.gz: ", "truncated or corrupt voxel data"}},
      {"ct_corrupt_metaimage",
       [](D d) { return with_mha_ct(d, [](std::string) { return std::string("\x89PNG\r\n\x1a\n garbage\n"); }); },
       {"ct.mha: ", "not a MetaImage header"}},
      {"ct_zero_spacing",
       [](D d) { return with_mha_ct(d, [](std::string h) { return replace_line(h, "ElementSpacing", "5 0 5"); }); },
       {"ct.mha: ", "ElementSpacing along axis 1 is 0"}},
      {"ct_negative_spacing",
       [](D d) { return with_mha_ct(d, [](std::string h) { return replace_line(h, "ElementSpacing", "5 5 -5"); }); },
       {"ct.mha: ", "ElementSpacing along axis 2 is -5"}},
      {"ct_dims_promising_terabytes",
       [](D d) {
         return with_mha_ct(d, [](std::string h) { return replace_line(h, "DimSize", "100000 100000 100000"); });
       },
       {"ct.mha: ", "absurd"}},
      {"ct_nonfinite_offset",
       [](D d) { return with_mha_ct(d, [](std::string h) { return replace_line(h, "Offset", "0 inf 0"); }); },
       {"ct.mha: ", "not finite"}},
      {"ct_nonfinite_nifti_sform",
       [](D d) {
         json s = tiny_case_scene_json();
         s["inputs"]["ct"] = "ct.nii";
         const std::string scene = write_tiny_case(d, s);
         write_volume(tiny_case_ct(), d.file("ct.nii"));
         std::string bytes = read_bytes(d.file("ct.nii"));
         const float bad = std::numeric_limits<float>::quiet_NaN();
         std::memcpy(&bytes[308], &bad, sizeof bad);   // srow_y[3]: nifti_1_header puts srow_y at byte 296
         write_bytes(d.file("ct.nii"), bytes);
         return scene;
       },
       {"ct.nii: ", "sform", "not finite"}},
      {"ct_nan_voxel", [nan](D d) { return with_ct_voxel(d, nan); },
       {"ct.nii.gz: ", "1 voxels are NaN or infinite", "(5, 6, 4)", "-1000 HU"}, 2, "out", kRolesCommands},
      {"ct_infinite_voxel", [inf](D d) { return with_ct_voxel(d, -inf); },
       {"ct.nii.gz: ", "NaN or infinite", "(5, 6, 4)"}, 2, "out", kRolesCommands},
      {"ct_all_air_with_labels",
       [](D d) {
         Volume ct = tiny_case_ct();
         for (int64_t n = 0; n < ct.voxel_count(); ++n) ct.data<float>()[n] = -1000.0f;
         return write_tiny_case(d, tiny_case_scene_json(), ct);
       },
       // The labels alone would make a wall and viscera of air, which the gas would lift.
       {"ct.nii.gz: ", "only 0 of 2560 voxels read as tissue or bone", "no body"}, 2, "out", kRolesCommands},
      {"port_aimed_at_a_missing_label",
       [](D d) {
         json s = tiny_case_scene_json();
         s["render"]["ports"] = {{{"name", "liver"}, {"skin_point_mm", {0, 0, 140}}, {"target_label", 99}}};
         return write_tiny_case(d, s);
       },
       // Refused before the solve: a run leaves nothing behind it.
       {"labels.nii.gz: ", "port 'liver': target_label 99 labels no voxel"}, 2, "out", {"run"}},
      {"labels_on_another_grid",
       [](D d) {
         Volume labels = tiny_case_labels();
         Geometry g = labels.geometry();
         g.origin_mm[0] += 2.5;   // half a voxel: a resampling slip
         Volume moved(g, VoxelType::UInt8);
         std::memcpy(moved.raw(), labels.raw(), labels.byte_count());
         return write_tiny_case(d, tiny_case_scene_json(), tiny_case_ct(), moved);
       },
       {"labels.nii.gz: ", "not on the grid of the CT", "origin", "resample"}},
      {"label_values_not_ids",
       [](D d) {
         const Volume l = tiny_case_labels();
         Volume f(l.geometry(), VoxelType::Float32);
         for (int64_t n = 0; n < l.voxel_count(); ++n) f.data<float>()[n] = l.data<uint8_t>()[n];
         f.data<float>()[7] = 2.5f;
         return write_tiny_case(d, tiny_case_scene_json(), tiny_case_ct(), f);
       },
       {"labels.nii.gz: ", "label value 2.5", "whole numbers"}},
      {"mapping_for_another_label_map", [](D d) { return with_scene(d, "/roles/viscera_labels", {17, 18}); },
       {"labels.nii.gz: ", "roles.viscera_labels (17, 18)", "its ids: 1, 2, 3"}, 2, "out", kRolesCommands},
      {"scene_wrong_type", [](D d) { return with_scene(d, "/load/pressure_mmhg", "12"); },
       {"scene.json: ", "load.pressure_mmhg = \"12\" has the wrong type"}},
      {"scene_wrong_unit",
       [](D d) {
         json s = tiny_case_scene_json();
         s["load"] = {{"pressure_kpa", 1.6}};
         return write_tiny_case(d, s);
       },
       {"scene.json: ", "pressure_kpa", "pressure_mmhg"}},
      {"scene_out_of_range", [](D d) { return with_scene(d, "/material/young_kpa", -60); },
       {"scene.json: ", "material.young_kpa"}},
      {"scene_not_json",
       [](D d) {
         const std::string scene = write_tiny_case(d);
         write_bytes(scene, "{\"load\": {\"pressure_mmhg\": 12,}}");
         return scene;
       },
       {"scene.json: ", "invalid JSON at line 1"}},
      {"scene_missing", [](D d) { return d.file("no_scene.json"); }, {"no_scene.json: "}},
      {"ct_missing", [](D d) { return with_scene(d, "/inputs/ct", "nowhere.nii.gz"); },
       {"nowhere.nii.gz: ", "does not exist"}},
      {"cavity_label_taken", [](D d) { return with_scene(d, "/output/cavity_label", 2); },
       {"labels.nii.gz: ", "already uses label 2", "output.cavity_label"}, 2, "out", {"run", "warp"}},
      {"out_under_a_file",
       [](D d) {
         write_bytes(d.file("blocker"), "a file, not a folder");
         return write_tiny_case(d);
       },
       {"blocker", "is not a folder"}, 2, "blocker/out", kFolderCommands},
      {"out_is_a_file",
       [](D d) {
         write_bytes(d.file("taken"), "a file, not a folder");
         return write_tiny_case(d);
       },
       {"taken: ", "not a folder"}, 2, "taken", kFolderCommands},
      {"no_cavity",
       [](D d) {
         json s = tiny_case_scene_json();
         s["roles"]["viscera_labels"] = json::array();
         s["roles"]["other_labels"] = {2};
         return write_tiny_case(d, s);
       },
       {"no cavity faces", "roles."}, 2, "out", kMeshCommands},
      {"everything_fixed",
       [](D d) {
         // Wall and viscera voxels in a checkerboard among fixed ones: every node of the 1-voxel cubes
         // touches a fixed voxel.
         Volume l = tiny_case_labels();
         const Geometry& g = l.geometry();
         for (int64_t k = 0; k < g.dims[2]; ++k)
           for (int64_t j = 0; j < g.dims[1]; ++j)
             for (int64_t i = 0; i < g.dims[0]; ++i)
               l.data<uint8_t>()[g.linear_index(i, j, k)] =
                   (k == 5 || k == 6) && tiny_case_label(i, j, k) != kTinyFixed && (i + j) % 2 == 0
                       ? (k == 6 ? kTinyWall : kTinyViscera)
                       : kTinyFixed;
         json s = tiny_case_scene_json();
         s["mesh"]["cube_voxels"] = 1;
         return write_tiny_case(d, s, tiny_case_ct(), l);
       },
       {"nodes is fixed", "nothing can move", "mesh.cube_voxels"}, 2, "out", kMeshCommands},
      {"wall_not_anchored",
       [](D d) {
         // The rim around the wall and the upper viscera becomes "other": the wall touches nothing fixed.
         Volume l = tiny_case_labels();
         const Geometry& g = l.geometry();
         for (int64_t k = 4; k < 8; ++k)
           for (int64_t j = 0; j < 16; ++j)
             for (int64_t i = 0; i < 16; ++i)
               if (tiny_case_label(i, j, k) == kTinyFixed) l.data<uint8_t>()[g.linear_index(i, j, k)] = 4;
         json s = tiny_case_scene_json();
         s["roles"]["other_labels"] = {4};
         return write_tiny_case(d, s, tiny_case_ct(), l);
       },
       {"wall part", "attached to no fixed node", "drift", "roles.fixed_labels"}, 2, "out", kMeshCommands},
      {"time_step_beyond_the_limit",
       [](D d) {
         json s = tiny_case_scene_json();
         s["material"] = springs_material_json();   // the explicit scheme takes the springs only
         s["solver"] = {{"method", "explicit"}, {"dt_ms", 5.0}};
         return write_tiny_case(d, s);
       },
       {"explicit diverged", "solver.dt_ms", "largest stable step"}, 1, "out", kMeshCommands},
  };
}

/// The error line with the case's folder left out: scratch folders are named after the test, and a
/// row's name must not supply the words its message is checked for.
std::string said(const CliResult& r, const ScratchDir& d) {
  std::string err = r.err;
  const std::string dir = d.path().string();
  for (std::size_t at; (at = err.find(dir)) != std::string::npos;) err.replace(at, dir.size(), "DIR");
  return err;
}

/// One row through one command.
struct Case {
  Row row;
  std::string command;
};

std::vector<Case> cases() {
  std::vector<Case> out;
  for (const Row& row : rows())
    for (const std::string& command : row.commands) out.push_back({row, command});
  return out;
}

Row row_named(const std::string& name) {
  for (const Row& row : rows())
    if (row.name == name) return row;
  throw std::logic_error("no row " + name);
}

void PrintTo(const Case& c, std::ostream* os) { *os << c.command << " " << c.row.name; }

/// `pneumo -q COMMAND SCENE --out DIR`.
CliResult run_command(const std::string& command, const std::string& scene, const std::string& out) {
  return run_pneumo("-q " + command + " " + scene + " --out " + out);
}

class HostileInput : public ::testing::TestWithParam<Case> {};

TEST_P(HostileInput, OneLineExitCodeAndNothingWritten) {
  const Row& row = GetParam().row;
  const std::string& command = GetParam().command;
  ScratchDir d;
  if (command == "warp") {   // a warp needs the simulation of the case it warps
    const CliResult sim = run_command("simulate", write_tiny_case(d), d.file(row.out));
    ASSERT_EQ(sim.code, 0) << sim.err;
  }
  const std::string scene = row.make(d);
  const std::set<std::string> before = tree(d.path());
  const CliResult r = run_command(command, scene, d.file(row.out));
  EXPECT_EQ(r.code, row.code) << r.err;
  ASSERT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  for (const std::string& words : row.expected) EXPECT_NE(said(r, d).find(words), std::string::npos) << r.err;
  EXPECT_TRUE(r.out.empty()) << r.out;
  EXPECT_EQ(tree(d.path()), before) << "something was written";
}

INSTANTIATE_TEST_SUITE_P(Table, HostileInput, ::testing::ValuesIn(cases()),
                         [](const ::testing::TestParamInfo<Case>& info) {
                           return info.param.command + "_" + info.param.row.name;
                         });

TEST(HostileInputControl, TheUnspoiledTinyCaseSimulates) {
  // Compared: the same command on the unspoiled case: exit 0 and metrics.json written, converged, the
  // wall lifted. Without this row the table above could pass on a case that never worked.
  ScratchDir d;
  const std::string scene = write_tiny_case(d);
  const CliResult r = run_command("simulate", scene, d.file("out"));
  ASSERT_EQ(r.code, 0) << r.err;
  const json m = json::parse(slurp(d.file("out/metrics.json")));
  EXPECT_TRUE(m["converged"].get<bool>());
  EXPECT_GT(m["max_wall_displacement_mm"].get<double>(), 0.1);
  EXPECT_EQ(m["inverted_tetrahedra"], 0);
}

TEST(HostileInputControl, TheUnspoiledTinyCaseWarpsRendersAndRuns) {
  // Compared: the table's other commands on the unspoiled case: each exits 0 and writes what marks it
  // done (warp: deformed_ct.nii.gz; render: render.json; run: report.html and a complete metrics.json).
  ScratchDir d;
  const std::string scene = write_tiny_case(d);
  ASSERT_EQ(run_command("simulate", scene, d.file("sim")).code, 0);
  const CliResult warp = run_command("warp", scene, d.file("sim"));
  ASSERT_EQ(warp.code, 0) << warp.err;
  EXPECT_TRUE(std::filesystem::exists(d.file("sim/deformed_ct.nii.gz")));
  const CliResult render = run_command("render", scene, d.file("render"));
  ASSERT_EQ(render.code, 0) << render.err;
  EXPECT_TRUE(std::filesystem::exists(d.file("render/render.json")));
  const CliResult run = run_command("run", scene, d.file("run"));
  ASSERT_EQ(run.code, 0) << run.err;
  EXPECT_TRUE(std::filesystem::exists(d.file("run/report.html")));
  EXPECT_TRUE(json::parse(slurp(d.file("run/metrics.json")))["pipeline_complete"].get<bool>());
}

/// Every file under `root` and its bytes.
std::map<std::string, std::string> contents(const std::filesystem::path& root) {
  std::map<std::string, std::string> out;
  for (const auto& e : std::filesystem::recursive_directory_iterator(root))
    if (e.is_regular_file()) out[std::filesystem::relative(e.path(), root).string()] = read_bytes(e.path().string());
  return out;
}

TEST(HostileInputRun, AForcedRunOnSpoiledInputLeavesTheEarlierResultsByteForByte) {
  // Compared: the folder of a finished run, file by file and byte by byte, before and after
  // `pneumo run --force` into it with one input spoiled at a time (the CT truncated, the labels off
  // the CT's grid, a scene value out of range: exit 2; a time step beyond the stable limit: exit 1,
  // the solve diverges). --force asks to replace the results, not to lose them to a run that fails.
  ScratchDir d;
  const std::string scene = write_tiny_case(d);
  ASSERT_EQ(run_command("run", scene, d.file("out")).code, 0);
  const std::map<std::string, std::string> earlier = contents(d.path() / "out");
  ASSERT_TRUE(earlier.count("report.html"));
  for (const char* spoil :
       {"ct_truncated_nifti_gz", "labels_on_another_grid", "scene_out_of_range", "time_step_beyond_the_limit"}) {
    SCOPED_TRACE(spoil);
    const Row row = row_named(spoil);
    const CliResult r = run_pneumo("-q run " + row.make(d) + " --out " + d.file("out") + " --force");
    EXPECT_EQ(r.code, row.code) << r.err;
    for (const std::string& words : row.expected) EXPECT_NE(said(r, d).find(words), std::string::npos) << r.err;
    EXPECT_TRUE(contents(d.path() / "out") == earlier) << "the earlier run's results changed";
  }
}

}  // namespace
}  // namespace pneumo
