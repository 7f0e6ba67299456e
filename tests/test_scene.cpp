// Scenes: the parameter table, the parser's messages, path resolution, the cross-key rules and the
// generated reference.
//
// What is compared: parsed values and echoed JSON exactly (no tolerance: numbers pass through
// JSON unchanged); error messages by the substrings a user needs (file, key path, value, what is
// allowed). The round trip and the range tests walk the table itself, so a key added to it is
// tested without touching this file.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>
#include <string>

#include "core/error.h"
#include "scene/param_table.h"
#include "scene/scene.h"
#include "scene/scene_presets.h"

namespace pneumo {
namespace {

namespace fs = std::filesystem;
using scene_detail::json;
using scene_detail::Kind;
using scene_detail::ParamInfo;
using scene_detail::TableDoc;

const char* const kOrigin = "/cases/abdomen/scene.json";  // never opened: parse_scene only names it

// The message of the InputError that parsing `j` throws, or "" when it parses.
std::string error_of(const json& j, const std::string& origin = kOrigin) {
  try {
    parse_scene(j, origin);
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_EQ(what.find('\n'), std::string::npos) << "messages are one line: " << what;
    return what;
  }
  return "";
}

#define EXPECT_CONTAINS(text, part) EXPECT_NE(std::string(text).find(part), std::string::npos) << (text)

std::string write_temp(const std::string& name, const std::string& text) {
  const fs::path dir = fs::path(::testing::TempDir()) / "pneumo_scene_tests";
  fs::create_directories(dir);
  const fs::path p = dir / name;
  std::ofstream(p, std::ios::binary) << text;
  return p.string();
}

// A scene with one item of every array, so that walking it reaches every key of every table.
json full_scene() {
  return json::parse(R"({
    "inputs": {"ct": "ct.nii.gz", "labels": "labels.nii.gz"},
    "mesh": {"roi_min_mm": [-10, -10, -10], "roi_max_mm": [10, 10, 10]},
    "material": {"label_young_kpa": [{"label": 3, "young_kpa": 5}]},
    "render": {
      "cameras": [{"name": "cam", "position_mm": [0, 0, 0], "look_at_mm": [0, 100, 0]}],
      "ports": [{"name": "port", "skin_point_mm": [0, 100, 0], "target_mm": [0, 50, 0]}],
      "paths": [{"name": "fly", "keyframes": [{"position_mm": [0, 0, 0], "look_at_mm": [0, 100, 0]},
                                              {"position_mm": [0, 10, 0], "look_at_mm": [0, 100, 0]}]}]
    }
  })");
}

// Visits every value key of `table` under `ptr` in `scene` (items of arrays: those present).
void for_each_key(const TableDoc& table, const json& scene, const json::json_pointer& ptr, const std::string& path,
                  const std::function<void(const ParamInfo&, const json::json_pointer&, const std::string&)>& f) {
  for (std::size_t i = 0; i < table.size(); ++i) {
    const ParamInfo& p = table.info(i);
    const std::string full = path.empty() ? p.key : path + "." + p.key;
    if (p.kind == Kind::Section) {
      for_each_key(*p.sub, scene, ptr / p.key, full, f);
    } else if (p.kind == Kind::ObjectArray) {
      const json& items = scene.at(ptr / p.key);
      for (std::size_t k = 0; k < items.size(); ++k)
        for_each_key(*p.sub, scene, ptr / p.key / k, full + "[" + std::to_string(k) + "]", f);
    } else {
      f(p, ptr / p.key, full);
    }
  }
}

// A valid value for key `p` that differs from `current` (null when there is none, e.g. a key whose
// only allowed value is its default).
json other_value(const ParamInfo& p, const json& current, int serial) {
  const auto ok = [&](const json& v) { return p.c.rule_ok == nullptr || p.c.rule_ok(v); };
  switch (p.kind) {
    case Kind::Bool: return !current.get<bool>();
    case Kind::Int:
    case Kind::Real: {
      const double base = current.is_null() ? 1.0 : current.get<double>();
      const auto& r = p.c.range;
      std::vector<double> candidates{base + 1, base - 1, r.lo, r.hi};
      if (p.kind == Kind::Real) candidates.insert(candidates.begin(), {base + 0.125, base - 0.125});
      if (std::isfinite(r.lo) && std::isfinite(r.hi)) candidates.insert(candidates.begin(), 0.5 * (r.lo + r.hi));
      for (double x : candidates) {
        if (p.kind == Kind::Int) x = std::floor(x);
        if (std::isfinite(x) && r.contains(x) && (current.is_null() || x != base))
          return p.kind == Kind::Int ? json(static_cast<int64_t>(x)) : json(x);
      }
      return nullptr;
    }
    case Kind::String:
      for (const json& v : {json("v" + std::to_string(serial)), json("opencl:1:2")})
        if (v != current && ok(v)) return v;
      return nullptr;
    case Kind::Path: return "sub/file" + std::to_string(serial) + ".nii.gz";
    case Kind::Enum: {
      const auto& c = p.choices;
      const auto at = std::find(c.begin(), c.end(), current.get<std::string>());
      return c[(at - c.begin() + 1) % c.size()];
    }
    case Kind::Vec3: {
      if (current.is_null()) return json::array({1.0, 2.0, 3.0});
      json v = current;
      for (int k = 0; k < 3; ++k) v[k] = v[k].get<double>() + 0.5 * (k + 1);
      return v;
    }
    case Kind::IdList: return json::array({100 + serial});
    case Kind::RealList: return json::array({5.0, 10.0});
    default: return nullptr;
  }
}

// ---- defaults ----------------------------------------------------------------------------------

TEST(SceneDefaults, MatchMethodAndTable) {
  const Scene s = default_scene();
  // method.md §4 (Nimura's values) and the choices written down in scene.h.
  // No cube size given: kDefaultCubeMm (9 mm, the balanced preset's) on any grid, 3 voxels on a 3 mm one.
  EXPECT_FALSE(s.mesh.cube_voxels.has_value());
  EXPECT_FALSE(s.mesh.cube_mm.has_value());
  Geometry three_mm;
  three_mm.dims = {10, 10, 10};
  three_mm.spacing_mm = Vec3::Constant(3.0);
  EXPECT_EQ(cube_voxels_for(s.mesh, three_mm), CubeVoxels(3));
  EXPECT_EQ(s.material.density_kg_m3, 1096.0);
  EXPECT_EQ(s.material.young_kpa, 60.0);
  EXPECT_EQ(s.material.damping_ratio, 0.4);
  EXPECT_EQ(s.material.spring_scale, 1.0);
  EXPECT_EQ(s.material.spring_model, SpringModel::Nonlinear);
  EXPECT_FALSE(s.material.gravity);
  EXPECT_EQ(s.load.pressure_mmhg, 12.0);
  EXPECT_EQ(s.solver.method, SolverMethod::Newton);
  // The material `pneumo bench` picks at every preset (docs/fidelity.md §4-5), one set for every CT.
  EXPECT_EQ(s.material.model, MaterialModel::FemNeoHookean);
  EXPECT_EQ(s.material.stiffening, 10.0);
  EXPECT_EQ(s.material.poisson_ratio, 0.45);
  EXPECT_EQ(s.material.viscera_young_kpa, 5.5);
  EXPECT_EQ(s.material.viscera_poisson_ratio, 0.49);
  EXPECT_EQ(s.material.liver_volume_loss, 0.12);
  EXPECT_EQ(s.material.fat_young_kpa, 3.0);
  EXPECT_EQ(s.solver.newmark_beta, 0.25);
  EXPECT_EQ(s.solver.newmark_gamma, 0.5);
  EXPECT_EQ(s.solver.kitasaka_step, 0.3);
  EXPECT_EQ(s.device, "cpu");
  EXPECT_EQ(s.roles.unlisted_label_role, Role::Other);
  EXPECT_EQ(s.roles.auto_body_threshold_hu, -500.0);
  EXPECT_EQ(s.roles.auto_bone_threshold_hu, 250.0);
  EXPECT_LE(s.render.step_fraction, 0.5);

  // An empty scene is the default scene, and the table's defaults are the struct's.
  EXPECT_EQ(parse_scene(json::object(), kOrigin).echo(), s.echo());
  EXPECT_EQ(scene_detail::scene_table().defaults(), s.echo());
  EXPECT_EQ(s.echo().at("$schema_version"), 1);
}

TEST(SceneDefaults, EveryDefaultIsAllowed) {
  // Each default passes its own key's checks: the default scene, echoed, reads back.
  const json echo = default_scene().echo();
  EXPECT_EQ(error_of(echo), "");
  EXPECT_EQ(parse_scene(echo, kOrigin).echo(), echo);
}

// ---- round trip --------------------------------------------------------------------------------

TEST(SceneRoundTrip, FullSceneEchoReadsBack) {
  const Scene a = parse_scene(full_scene(), kOrigin);
  const Scene b = parse_scene(a.echo(), "/elsewhere/echo.json");  // paths are absolute by now
  EXPECT_EQ(b.echo(), a.echo());
}

TEST(SceneRoundTrip, EveryKeyChangesItsOwnValueOnly) {
  // For each key: set a non-default value, parse, echo; the echo must hold that value at that key
  // and nothing else may change. Catches a key bound to the wrong field and a field never written.
  const json base_json = full_scene();
  const json base = parse_scene(base_json, kOrigin).echo();
  int serial = 0, tested = 0;
  for_each_key(scene_detail::scene_table(), base, json::json_pointer(), "",
               [&](const ParamInfo& p, const json::json_pointer& ptr, const std::string& path) {
    json value = other_value(p, base.at(ptr), ++serial);
    if (value.is_null()) return;  // $schema_version: its default is its only value
    // Transfer-function points come in pairs/quadruples and only with preset "custom".
    if (path == "render.custom_opacity") value = json::array({-100.0, 0.0, 100.0, 1.0});
    if (path == "render.custom_colour") value = json::array({0.0, 1.0, 0.0, 0.0});
    json changed = base;
    changed[ptr] = value;
    std::vector<json::json_pointer> companions;  // keys that must change with this one
    if (path == "material.model") {   // the finite elements need the Newton solver (scene_validate.cpp)
      companions.push_back(json::json_pointer("/solver/method"));
      changed[companions.back()] = "newton";
      companions.push_back(json::json_pointer("/material/stiffening"));   // the co-rotational law has none
      changed[companions.back()] = 0.0;
    }
    if (path == "material.spring_model" || path == "material.volume_stiffness_kpa") {   // the springs' own keys
      companions.push_back(json::json_pointer("/material/model"));
      changed[companions.back()] = "msd";
    }
    if (path == "material.tilt_deg") {   // a tilt needs gravity (scene_validate.cpp)
      companions.push_back(json::json_pointer("/material/gravity"));
      changed[companions.back()] = true;
    }
    if (path == "render.ports[0].target_label") {
      companions.push_back(ptr.parent_pointer() / "target_mm");
      changed[companions.back()] = nullptr;
    }
    if (path == "render.custom_opacity" || path == "render.custom_colour") {
      const auto render = ptr.parent_pointer();
      companions.push_back(render / "preset");
      changed[companions.back()] = "custom";
      const char* other = path == "render.custom_opacity" ? "custom_colour" : "custom_opacity";
      companions.push_back(render / other);
      changed[companions.back()] = path == "render.custom_opacity" ? json::array({0.0, 1.0, 0.0, 0.0})
                                                                  : json::array({-100.0, 0.0, 100.0, 1.0});
    }
    SCOPED_TRACE(path + " = " + value.dump());
    const std::string err = error_of(changed);
    ASSERT_EQ(err, "");
    json echo = parse_scene(changed, kOrigin).echo();
    const json expected = p.kind == Kind::Path ? json("/cases/abdomen/" + value.get<std::string>()) : value;
    EXPECT_EQ(echo.at(ptr), expected);
    echo[ptr] = base.at(ptr);
    for (const auto& c : companions) echo[c] = base.at(c);
    EXPECT_EQ(echo, base) << "changing " << path << " changed other keys";
    ++tested;
  });
  EXPECT_GT(tested, 100);
}

// ---- unknown keys ------------------------------------------------------------------------------

TEST(SceneErrors, UnknownKeyTopLevelSuggestsWhereItBelongs) {
  const std::string e = error_of({{"presure_mmhg", 12}});
  EXPECT_CONTAINS(e, kOrigin);
  EXPECT_CONTAINS(e, "presure_mmhg is an unknown key");
  EXPECT_CONTAINS(e, "did you mean load.pressure_mmhg?");
  EXPECT_CONTAINS(error_of({{"lod", json::object()}}), "did you mean load?");
}

TEST(SceneErrors, UnknownKeyNestedSuggestsClosest) {
  EXPECT_CONTAINS(error_of({{"load", {{"presure_mmhg", 12}}}}), "load.presure_mmhg is an unknown key; did you mean load.pressure_mmhg?");
  // A key without its unit suffix is the likeliest slip.
  EXPECT_CONTAINS(error_of({{"material", {{"young", 30}}}}), "did you mean material.young_kpa?");
  // Nothing close: the known keys of that object are listed.
  const std::string e = error_of({{"mesh", {{"zzzzzzzzzz", 1}}}});
  EXPECT_CONTAINS(e, "mesh.zzzzzzzzzz is an unknown key; known keys in mesh: cube_voxels, cube_mm, model");
}

TEST(SceneErrors, UnknownKeyInArrayItemCarriesIndex) {
  json j = full_scene();
  j["render"]["cameras"].push_back({{"name", "b"}, {"position_mm", {0, 0, 0}}, {"look_at_mm", {1, 0, 0}}, {"fov", 60}});
  EXPECT_CONTAINS(error_of(j), "render.cameras[1].fov is an unknown key; did you mean render.cameras[1].fov_deg?");
}

TEST(SceneErrors, EnumValueSuggestsClosest) {
  const std::string e = error_of({{"solver", {{"method", "newmark-beta"}}}});
  EXPECT_CONTAINS(e, "solver.method = \"newmark-beta\" is not allowed");
  EXPECT_CONTAINS(e, "\"static\", \"explicit\", \"newmark\", \"kitasaka2004\"");
  EXPECT_CONTAINS(e, "did you mean \"newmark\"?");
}

// ---- ranges ------------------------------------------------------------------------------------

TEST(SceneErrors, OutOfRangeSamples) {
  struct Case { json scene; std::string path, value, allowed; };
  const std::vector<Case> cases{
      {{{"load", {{"pressure_mmhg", 150}}}}, "load.pressure_mmhg", "150", "allowed: 0 to 100 mmHg"},
      {{{"mesh", {{"cube_voxels", 0}}}}, "mesh.cube_voxels", "0", "allowed: 1 to 64"},
      {{{"material", {{"damping_ratio", -1}}}}, "material.damping_ratio", "-1", "allowed: 0 to 10"},
      {{{"material", {{"young_kpa", 0}}}}, "material.young_kpa", "0", "allowed: 0.1 to 1000000 kPa"},
      // Values that parse yet make the forces vanish against rounding (NaN, or no end): refused at
      // the physical floors.
      {{{"material", {{"young_kpa", 1e-100}}}}, "material.young_kpa", "1e-100", "allowed: 0.1 to 1000000 kPa"},
      {{{"material", {{"wall_young_kpa", 1e-300}}}}, "material.wall_young_kpa", "1e-300", "allowed: 0.1 to 1000000 kPa"},
      {{{"material", {{"label_young_kpa", {{{"label", 3}, {"young_kpa", 1e-300}}}}}}},
       "material.label_young_kpa[0].young_kpa", "1e-300", "allowed: 0.1 to 1000000 kPa"},
      {{{"material", {{"spring_scale", 1e-300}}}}, "material.spring_scale", "1e-300", "allowed: 0.01 to 10"},
      {{{"solver", {{"dt_safety", 0}}}}, "solver.dt_safety", "0", "allowed: > 0 and <= 1"},
      {{{"render", {{"step_fraction", 0.6}}}}, "render.step_fraction", "0.6", "allowed: > 0 and <= 0.5"},
      {{{"roles", {{"wall_labels", {1, 70000}}}}}, "roles.wall_labels[1]", "70000", "allowed: 0 to 65535"},
      {{{"load", {{"pressure_curve_mmhg", {0, 200}}}}}, "load.pressure_curve_mmhg[1]", "200", "allowed: 0 to 100 mmHg"},
      {{{"$schema_version", 2}}, "$schema_version", "2", "allowed: 1"},
  };
  for (const Case& c : cases) {
    const std::string e = error_of(c.scene);
    EXPECT_CONTAINS(e, kOrigin);
    EXPECT_CONTAINS(e, c.path + " = " + c.value + " is out of range; " + c.allowed);
  }
}

TEST(SceneErrors, EveryBoundIsEnforced) {
  // Just outside each finite bound of each numeric key (items of the full scene included): an
  // error naming the key's path, the value and the allowed range.
  const json base = parse_scene(full_scene(), kOrigin).echo();
  int tested = 0;
  for_each_key(scene_detail::scene_table(), base, json::json_pointer(), "",
               [&](const ParamInfo& p, const json::json_pointer& ptr, const std::string& path) {
    if (p.kind != Kind::Int && p.kind != Kind::Real) return;
    const auto& r = p.c.range;
    for (double bad : {r.lo - (r.lo_open ? 0.0 : 1.0), r.hi + (r.hi_open ? 0.0 : 1.0)}) {
      if (!std::isfinite(bad)) continue;
      json j = base;
      j[ptr] = p.kind == Kind::Int ? json(static_cast<int64_t>(bad)) : json(bad);
      const std::string e = error_of(j);
      EXPECT_CONTAINS(e, path + " = " + scene_detail::show(j[ptr]) + " is out of range; allowed: " + r.text());
      ++tested;
    }
  });
  EXPECT_GT(tested, 80);
}

TEST(SceneErrors, RulesBeyondRanges) {
  EXPECT_CONTAINS(error_of({{"load", {{"pressure_curve_mmhg", {5, 10, 8}}}}}),
                  "load.pressure_curve_mmhg = [5,10,8] is not allowed; non-decreasing");
  // A positive pressure too small to move the wall past rounding: refused; 0 (rest) is allowed.
  EXPECT_CONTAINS(error_of({{"load", {{"pressure_mmhg", 1e-9}}}}),
                  "load.pressure_mmhg = 1e-09 is not allowed; 0 (rest) or at least 0.1");
  EXPECT_EQ(error_of({{"load", {{"pressure_mmhg", 0}}}}), "");
  EXPECT_EQ(error_of({{"load", {{"pressure_mmhg", 0.1}}}}), "");
  EXPECT_CONTAINS(error_of({{"load", {{"pressure_curve_mmhg", {0, 0.01, 5}}}}}),
                  "is not allowed; non-decreasing, each 0 (rest) or at least 0.1");
  EXPECT_EQ(error_of({{"load", {{"pressure_curve_mmhg", {0, 0.5, 5}}}}}), "");
  EXPECT_CONTAINS(error_of({{"device", "gpu"}}), "device = \"gpu\" is not allowed; \"cpu\", \"auto\", \"opencl\", \"opencl:P:D\"");
  EXPECT_NE(error_of({{"device", "opencl:0"}}), "");
  EXPECT_NE(error_of({{"device", "opencl:a:1"}}), "");
  EXPECT_EQ(error_of({{"device", "opencl:1:0"}}), "");
  EXPECT_EQ(error_of({{"device", "opencl"}}), "");
  EXPECT_EQ(error_of({{"device", "auto"}}), "");
  EXPECT_EQ(error_of({{"$schema_version", 1}}), "");
  json j = full_scene();
  j["render"]["cameras"][0]["name"] = "a/b";
  EXPECT_CONTAINS(error_of(j), "render.cameras[0].name = \"a/b\" is not allowed");
  j = full_scene();
  j["render"]["cameras"][0]["up"] = {0, 0, 0};
  EXPECT_CONTAINS(error_of(j), "render.cameras[0].up = [0,0,0] is not allowed");
  EXPECT_CONTAINS(error_of({{"roles", {{"fixed_labels", {4, 4}}}}}), "roles.fixed_labels[1] = 4 is listed twice");
}

// ---- types -------------------------------------------------------------------------------------

TEST(SceneErrors, WrongTypesNameKeyValueAndType) {
  struct Case { json scene; std::string expect; };
  const std::vector<Case> cases{
      {{{"load", {{"pressure_mmhg", "12"}}}}, "load.pressure_mmhg = \"12\" has the wrong type; expected a number"},
      {{{"load", {{"pressure_mmhg", nullptr}}}}, "load.pressure_mmhg = null has the wrong type; expected a number"},
      {{{"mesh", {{"cube_voxels", 8.5}}}}, "mesh.cube_voxels = 8.5 has the wrong type; expected an integer"},
      {{{"mesh", {{"roi_min_mm", {1, 2}}}}}, "mesh.roi_min_mm = [1,2] has the wrong type; expected an array of 3 numbers or null"},
      {{{"mesh", {{"roi_min_mm", {1, "2", 3}}}}}, "expected an array of 3 numbers"},
      {{{"material", {{"gravity", "yes"}}}}, "material.gravity = \"yes\" has the wrong type; expected true or false"},
      {{{"solver", {{"method", 2}}}}, "solver.method = 2 has the wrong type; expected one of \"static\""},
      {{{"roles", {{"wall_labels", {"skin"}}}}}, "roles.wall_labels[0] = \"skin\" has the wrong type; expected an integer"},
      {{{"roles", {{"wall_labels", 3}}}}, "roles.wall_labels = 3 has the wrong type; expected an array of integers"},
      {{{"inputs", json::array()}}, "inputs = [] has the wrong type; expected an object"},
      {{{"inputs", {{"ct", 5}}}}, "inputs.ct = 5 has the wrong type; expected a path (string) or null"},
      {{{"render", {{"cameras", json::object()}}}}, "render.cameras = {} has the wrong type; expected an array of objects"},
      {{{"render", {{"cameras", json::array({1})}}}}, "render.cameras[0] = 1 has the wrong type; expected an object"},
      {{{"name", 3}}, "name = 3 has the wrong type; expected a string"},
      {json::array(), "the scene = [] has the wrong type; expected an object"},
  };
  for (const Case& c : cases) EXPECT_CONTAINS(error_of(c.scene), c.expect);
  // An integer written as a float is still an integer.
  EXPECT_EQ(parse_scene({{"mesh", {{"cube_voxels", 4.0}}}}, kOrigin).mesh.cube_voxels, 4);
}

// ---- paths -------------------------------------------------------------------------------------

TEST(ScenePaths, RelativeResolveAgainstSceneFolderAbsoluteUntouched) {
  const Scene s = parse_scene({{"inputs", {{"ct", "ct.nii.gz"}, {"labels", "../shared/labels.nii.gz"}}},
                               {"output", {{"folder", "/abs/out"}}}},
                              kOrigin);
  EXPECT_EQ(s.inputs.ct, "/cases/abdomen/ct.nii.gz");
  EXPECT_EQ(s.inputs.labels, "/cases/shared/labels.nii.gz");
  EXPECT_EQ(s.output.folder, "/abs/out");
  EXPECT_EQ(s.folder, "/cases/abdomen");
  EXPECT_EQ(s.path, kOrigin);
  // Unset paths stay unset, and echo as null.
  const Scene d = parse_scene(json::object(), kOrigin);
  EXPECT_EQ(d.inputs.ct, "");
  EXPECT_TRUE(d.echo()["inputs"]["ct"].is_null());
}

TEST(ScenePaths, LoadSceneResolvesAgainstTheFilesFolder) {
  const std::string path = write_temp("paths.json", R"({"inputs": {"ct": "data/ct.nii.gz"}})");
  const Scene s = load_scene(path);
  EXPECT_EQ(s.inputs.ct, (fs::absolute(path).parent_path() / "data/ct.nii.gz").lexically_normal().string());
}

TEST(ScenePaths, RequireCt) {
  const Scene none = parse_scene(json::object(), kOrigin);
  try {
    none.require_ct();
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_CONTAINS(e.what(), kOrigin);
    EXPECT_CONTAINS(e.what(), "inputs.ct");
  }
  EXPECT_EQ(parse_scene({{"inputs", {{"ct", "a.nii"}}}}, kOrigin).require_ct(), "/cases/abdomen/a.nii");
}

// ---- cross-key rules ---------------------------------------------------------------------------

TEST(SceneRules, LabelInTwoRoleListsNamesBoth) {
  const std::string e = error_of({{"roles", {{"wall_labels", {1, 5}}, {"viscera_labels", json::array({5})}}}});
  EXPECT_CONTAINS(e, "label 5 is in both roles.wall_labels and roles.viscera_labels");
}

TEST(SceneRules, AnAttachedLabelWithAnotherRoleIsRefused) {
  const json attached = {{"attached_labels", {2, 7}}};
  for (const char* key : {"viscera_labels", "fixed_labels", "other_labels"}) {
    const std::string e = error_of({{"roles", {{"wall_labels", {2}}, {key, json::array({7})}}}, {"mesh", attached}});
    EXPECT_CONTAINS(e, "mesh.attached_labels[1]");
    EXPECT_CONTAINS(e, std::string("is in roles.") + key);
  }
  // A wall label, or one no list names (the automatic roles decide it), is accepted.
  EXPECT_NO_THROW(parse_scene({{"roles", {{"wall_labels", {2}}}}, {"mesh", attached}}, kOrigin));
}

TEST(SceneRules, RoiBothOrNeitherAndOrdered) {
  EXPECT_CONTAINS(error_of({{"mesh", {{"roi_min_mm", {0, 0, 0}}}}}),
                  "mesh.roi_min_mm is set but mesh.roi_max_mm is not");
  EXPECT_CONTAINS(error_of({{"mesh", {{"roi_min_mm", {0, 0, 0}}, {"roi_max_mm", {1, 0, 1}}}}}),
                  "mesh.roi_max_mm = [1.0,0.0,1.0] must exceed mesh.roi_min_mm");
}

TEST(SceneRules, LandmarksNamedOnceMeasuredInPairsAndAtLeastThree) {
  // Compared: the messages for the rules of §9's evaluation: a name twice, a measurement without its
  // partner, and fewer than the 3 measured points Horn's alignment needs; a valid list parses.
  auto mark = [](const std::string& name, bool before, bool after) {
    json m = {{"name", name}, {"ct_mm", {1, 2, 3}}};
    if (before) m["measured_before_mm"] = {0, 0, 0};
    if (after) m["measured_after_mm"] = {0, 1, 0};
    return m;
  };
  EXPECT_CONTAINS(error_of({{"landmarks", {mark("a", false, false), mark("a", false, false)}}}),
                  "landmarks[1].name = \"a\" is used twice (also landmarks[0])");
  EXPECT_CONTAINS(error_of({{"landmarks", {mark("a", true, false)}}}),
                  "landmarks[0] gives measured_before_mm without measured_after_mm");
  EXPECT_CONTAINS(error_of({{"landmarks", {mark("a", true, true), mark("b", true, true), mark("c", false, false)}}}),
                  "needs at least 3");
  EXPECT_EQ(error_of({{"landmarks", {mark("a", true, true), mark("b", true, true), mark("c", true, true),
                                     mark("port", false, false)}}}),
            "");
}

TEST(SceneRules, CameraItemErrorsCarryTheIndex) {
  json j = full_scene();
  j["render"]["cameras"].push_back({{"name", "b"}, {"position_mm", {0, 0, 0}}, {"look_at_mm", {1, 0, 0}}, {"fov_deg", 200}});
  EXPECT_CONTAINS(error_of(j), "render.cameras[1].fov_deg = 200 is out of range; allowed: > 0 and <= 180 deg");
  j["render"]["cameras"][1] = {{"name", "b"}, {"look_at_mm", {1, 0, 0}}};
  EXPECT_CONTAINS(error_of(j), "render.cameras[1].position_mm is missing; it is required");
  j["render"]["cameras"][1] = {{"name", "b"}, {"position_mm", {0, 0, 0}}, {"look_at_mm", {0, 0, 5}}};
  EXPECT_CONTAINS(error_of(j), "render.cameras[1].up = [0.0,0.0,1.0] is parallel to the scope's axis");
  j["render"]["cameras"][1] = {{"name", "b"}, {"position_mm", {0, 0, 0}}, {"look_at_mm", {0, 0, 0}}};
  EXPECT_CONTAINS(error_of(j), "render.cameras[1].look_at_mm = [0.0,0.0,0.0] equals position_mm");
  j["render"]["cameras"][1] = {{"name", "b"}, {"position_mm", {0, 0, 0}}, {"look_at_mm", {1, 0, 0}}, {"fov_deg", 180}};
  EXPECT_CONTAINS(error_of(j), "render.cameras[1].fov_deg = 180.0 is not allowed with lens \"pinhole\"");
  j["render"]["cameras"][1]["lens"] = "fisheye";
  EXPECT_EQ(error_of(j), "");
  j["render"]["cameras"][1]["name"] = "port";
  EXPECT_CONTAINS(error_of(j), "render.ports[0].name = \"port\" is used twice (also render.cameras[1])");
}

TEST(SceneRules, PortTargetsAndPathKeyframes) {
  json j = full_scene();
  j["render"]["ports"][0]["target_label"] = 7;
  EXPECT_CONTAINS(error_of(j), "render.ports[0] gives both target_mm and target_label");
  j["render"]["ports"][0].erase("target_mm");
  EXPECT_EQ(error_of(j), "");
  j["render"]["ports"][0].erase("target_label");
  EXPECT_CONTAINS(error_of(j), "render.ports[0] gives neither target_mm nor target_label");
  j = full_scene();
  j["render"]["paths"][0]["keyframes"].erase(1);
  EXPECT_CONTAINS(error_of(j), "render.paths[0].keyframes = [{");
  EXPECT_CONTAINS(error_of(j), "has 1 items; allowed: 2 or more items");
  j = full_scene();
  j["render"]["paths"][0]["keyframes"][1]["look_at_mm"] = {0, 10, 0};
  EXPECT_CONTAINS(error_of(j), "render.paths[0].keyframes[1].look_at_mm = [0.0,10.0,0.0] equals position_mm");
  j = full_scene();
  j["material"]["label_young_kpa"].push_back({{"label", 3}, {"young_kpa", 9}});
  EXPECT_CONTAINS(error_of(j), "material.label_young_kpa[1].label = 3 is listed twice (also material.label_young_kpa[0])");
}

TEST(SceneRules, FiniteElementsNeedAStaticSolverAndRefuseTheSpringsOwnKeys) {
  // Each rule of check_material_model, with the message a user reads.
  // The co-rotational law is linear: chosen without a stiffening of its own, it takes 0, not the default's b.
  EXPECT_EQ(parse_scene({{"material", {{"model", "fem-corotational"}}}}, kOrigin).material.stiffening, 0.0);
  // The linear law gets no 3 kPa fat unless the scene asks for it (scene_parse.cpp, model_patch).
  EXPECT_FALSE(parse_scene({{"material", {{"model", "fem-corotational"}}}}, kOrigin).material.fat_young_kpa);
  EXPECT_EQ(parse_scene({{"material", {{"model", "fem-corotational"}, {"fat_young_kpa", 3}}}}, kOrigin)
                .material.fat_young_kpa,
            3.0);
  EXPECT_EQ(parse_scene(json::object(), kOrigin).material.fat_young_kpa, 3.0);
  EXPECT_EQ(parse_scene({{"material", {{"model", "fem-neohookean"}}}}, kOrigin).material.stiffening, 10.0);
  EXPECT_NO_THROW(parse_scene({{"material", {{"model", "fem-corotational"}}}, {"solver", {{"method", "static"}}}},
                              kOrigin));
  EXPECT_NO_THROW(parse_scene({{"material", {{"model", "fem-corotational"}}}, {"solver", {{"method", "implicit-euler"}}}},
                              kOrigin));
  const json fem = {{"material", {{"model", "fem-corotational"}}}, {"solver", {{"method", "explicit"}}}};
  EXPECT_CONTAINS(error_of(fem),
                  "solver.method = \"explicit\" cannot solve material.model \"fem-corotational\"; use \"newton\", "
                  "\"static\" or \"implicit-euler\"");
  json j = {{"material", {{"model", "fem-corotational"}, {"stiffening", 5}}}, {"solver", {{"method", "newton"}}}};
  EXPECT_CONTAINS(error_of(j), "material.stiffening = 5");
  j = {{"material", {{"model", "fem-neohookean"}, {"volume_stiffness_kpa", 60}}}, {"solver", {{"method", "newton"}}}};
  EXPECT_CONTAINS(error_of(j), "material.volume_stiffness_kpa = 60");
  // The springs have no fibres: asking for the wall's is refused, not ignored.
  j = {{"material", {{"model", "msd"}, {"wall_fibre_stiffness", 0.67}}}, {"solver", {{"method", "newton"}}}};
  EXPECT_CONTAINS(error_of(j), "material.wall_fibre_stiffness = 0.67 needs finite elements");
  EXPECT_NO_THROW(parse_scene({{"material", {{"wall_fibre_stiffness", 0.67}, {"wall_fibre_exponent", 2}}}}, kOrigin));
  j = {{"material", {{"model", "fem-neohookean"}, {"stiffening", 5}, {"wall_poisson_ratio", 0.49},
                     {"viscera_poisson_ratio", nullptr}}},
       {"solver", {{"method", "newton"}}}};
  const Scene s = parse_scene(j, kOrigin);
  EXPECT_DOUBLE_EQ(s.poisson_for(Role::Wall, 0), 0.49);
  EXPECT_DOUBLE_EQ(s.poisson_for(Role::Viscera, 0), 0.45);
}

TEST(SceneRules, Queries) {
  Scene s = parse_scene({{"roles", {{"wall_labels", json::array({2})}, {"viscera_labels", {5, 6}}, {"fixed_labels", json::array({9})},
                                    {"unlisted_label_role", "viscera"}}},
                         {"material", {{"young_kpa", 50}, {"wall_young_kpa", 24}, {"viscera_young_kpa", nullptr},
                                       {"fat_young_kpa", nullptr},
                                       {"label_young_kpa", json::array({{{"label", 6}, {"young_kpa", 3}}})}}}},
                        kOrigin);
  const std::vector<Role> roles = s.roles.label_roles();
  ASSERT_EQ(roles.size(), 65536u);
  EXPECT_EQ(roles[2], Role::Wall);
  EXPECT_EQ(roles[5], Role::Viscera);
  EXPECT_EQ(roles[9], Role::Fixed);
  EXPECT_EQ(roles[0], Role::Viscera);
  EXPECT_EQ(s.young_kpa_for(Role::Wall, 2), 24.0);
  EXPECT_EQ(s.young_kpa_for(Role::Viscera, 5), 50.0);
  EXPECT_EQ(s.young_kpa_for(Role::Viscera, 6), 3.0);
  // Fat by HU: off when null; on, inside [-190, -30] HU (ends included) unless the label has its own E.
  EXPECT_EQ(s.young_kpa_for(Role::Wall, 2, -100.0f), 24.0);
  s.material.fat_young_kpa = 2.0;
  EXPECT_EQ(s.young_kpa_for(Role::Wall, 2, -100.0f), 2.0);
  EXPECT_EQ(s.young_kpa_for(Role::Viscera, 5, -190.0f), 2.0);
  EXPECT_EQ(s.young_kpa_for(Role::Wall, 2, -30.0f), 2.0);
  EXPECT_EQ(s.young_kpa_for(Role::Wall, 2, -29.0f), 24.0);
  EXPECT_EQ(s.young_kpa_for(Role::Wall, 2, -191.0f), 24.0);
  EXPECT_EQ(s.young_kpa_for(Role::Viscera, 6, -100.0f), 3.0);
  EXPECT_EQ(s.effective_volume_stiffness_kpa(), 0.0);
  s.solver.method = SolverMethod::Kitasaka2004;
  EXPECT_EQ(s.effective_volume_stiffness_kpa(), 50.0);
  s.material.volume_stiffness_kpa = 7.0;
  EXPECT_EQ(s.effective_volume_stiffness_kpa(), 7.0);
  EXPECT_STREQ(role_name(Role::Fixed), "fixed");
  EXPECT_STREQ(enum_name(RenderPreset::CtSoftTissue), "ct-soft-tissue");
}

TEST(SceneRules, TheLungsMaterialIsAeratedWallUnlabelledOrNamedLung) {
  // The defaults: 1 kPa and ν 0.40 at or below -500 HU, for wall voxels without a label or with one the
  // names call lung (roles.lung_ids); a labelled duodenum's gas (19), viscera, tissue above the window
  // and everything with roles.compliant_lungs off keep their own.
  Scene s = parse_scene(json::object(), kOrigin);
  s.roles.lung_ids = {11, 14};
  EXPECT_EQ(s.young_kpa_for(Role::Wall, 0, -850.0f), 1.0);
  EXPECT_EQ(s.young_kpa_for(Role::Wall, 14, -500.0f), 1.0);
  EXPECT_DOUBLE_EQ(s.poisson_for(Role::Wall, 11, -700.0f), 0.40);
  EXPECT_EQ(s.young_kpa_for(Role::Wall, 14, -499.0f), 60.0);
  EXPECT_EQ(s.young_kpa_for(Role::Wall, 19, -1000.0f), 60.0);
  EXPECT_DOUBLE_EQ(s.poisson_for(Role::Wall, 19, -1000.0f), 0.45);
  EXPECT_EQ(s.young_kpa_for(Role::Viscera, 0, -1000.0f), 5.5);
  EXPECT_DOUBLE_EQ(s.poisson_for(Role::Viscera, 0, -1000.0f), 0.49);
  s.material.label_young_kpa = {{14, 2.0, std::nullopt}};
  EXPECT_EQ(s.young_kpa_for(Role::Wall, 14, -850.0f), 2.0);
  EXPECT_DOUBLE_EQ(s.poisson_for(Role::Wall, 14, -850.0f), 0.45);   // its own E, its role's ν
  s.roles.compliant_lungs = false;
  EXPECT_EQ(s.young_kpa_for(Role::Wall, 0, -850.0f), 60.0);
  EXPECT_DOUBLE_EQ(s.poisson_for(Role::Wall, 0, -850.0f), 0.45);
}

TEST(SceneRules, TheLiverKeepsTheViscerasShearAndTakesTheBulkModulusItsBloodGives) {
  // liver_volume_loss 0.12 at 12 mmHg (1.59987 kPa): K = p / -ln(0.88) = 12.516 kPa, the Kirchhoff mean
  // stress of the neo-Hookean law at J = 0.88 under p. μ stays the viscera's, 5.5 / (2 × 1.49) kPa.
  // Derived back from the E and ν the scene gives, so a slip in either formula shows.
  Scene s = parse_scene(json::object(), kOrigin);
  s.roles.liver_ids = {5};
  const double e = s.young_kpa_for(Role::Viscera, 5, 60.0f), nu = s.poisson_for(Role::Viscera, 5, 60.0f);
  const double mu = e / (2.0 * (1.0 + nu)), k = e / (3.0 * (1.0 - 2.0 * nu));
  EXPECT_NEAR(mu, 5.5 / (2.0 * 1.49), 1e-12);
  EXPECT_NEAR(k, 12.0 * 0.133322387415 / -std::log(0.88), 1e-9);
  EXPECT_LT(nu, 0.49);   // the liver gives way more than the other viscera
  // Not the liver, not viscera, its own E in label_young_kpa, or the effect off: the role's moduli.
  EXPECT_EQ(s.young_kpa_for(Role::Viscera, 6, 60.0f), 5.5);
  EXPECT_DOUBLE_EQ(s.poisson_for(Role::Viscera, 6, 60.0f), 0.49);
  EXPECT_EQ(s.young_kpa_for(Role::Wall, 5, 60.0f), 60.0);
  s.material.label_young_kpa = {{5, 4.0, std::nullopt}};
  EXPECT_EQ(s.young_kpa_for(Role::Viscera, 5, 60.0f), 4.0);
  EXPECT_DOUBLE_EQ(s.poisson_for(Role::Viscera, 5, 60.0f), 0.49);
  s.material.label_young_kpa.clear();
  s.material.liver_volume_loss.reset();
  EXPECT_EQ(s.young_kpa_for(Role::Viscera, 5, 60.0f), 5.5);
  // A loss so small that the bulk modulus would pass ν's bound of the table keeps ν at 0.49 and μ.
  s.material.liver_volume_loss = 0.001;
  EXPECT_DOUBLE_EQ(s.poisson_for(Role::Viscera, 5, 60.0f), 0.49);
  EXPECT_DOUBLE_EQ(s.young_kpa_for(Role::Viscera, 5, 60.0f), 5.5);
  // The springs have no bulk modulus to give it.
  s.material.liver_volume_loss = 0.12;
  s.material.model = MaterialModel::Msd;
  EXPECT_EQ(s.young_kpa_for(Role::Viscera, 5, 60.0f), 5.5);
}

TEST(SceneRules, TheLiversIdsComeFromTheNamesTheLabelMapCarries) {
  const std::string names = write_temp("liver_names.csv", "label_id,name\n1,spleen\n5,liver\n6,Liver Segment 4\n7,liver_tumor\n8,caudate lobe\n");
  const std::string labels = write_temp("liver_labels.nii.gz", "");
  Scene s = parse_scene({{"inputs", {{"labels", labels}, {"label_names", names}}}}, kOrigin);
  EXPECT_EQ(s.roles.liver_ids, (std::vector<int>{5, 6, 8}));
}

// ---- files -------------------------------------------------------------------------------------

TEST(SceneFiles, MalformedJsonGivesLineAndColumn) {
  const std::string path = write_temp("bad.json", "{\n  \"name\": \"x\",\n  \"load\": {\n    \"pressure_mmhg\": 12,\n  }\n}\n");
  try {
    load_scene(path);
    FAIL() << "no error";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_EQ(what.rfind(path + ": invalid JSON at line 5, column 3", 0), 0u) << what;
  }
}

TEST(SceneFiles, MissingFileDuplicateKeysAndComments) {
  try {
    load_scene("/nonexistent/scene.json");
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_CONTAINS(e.what(), "/nonexistent/scene.json: the scene file does not exist");
  }
  const std::string dup = write_temp("dup.json", R"({"render": {"cameras": [{"name": "a", "name": "b"}]}})");
  try {
    load_scene(dup);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_CONTAINS(e.what(), "render.cameras[0].name is given twice");
  }
  const std::string huge = write_temp("huge.json", R"({"load": {"pressure_mmhg": 1e999}})");
  try {
    load_scene(huge);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_CONTAINS(e.what(), "huge.json: invalid JSON: number overflow");
  }
  const std::string commented = write_temp("comments.json", "{\n  // clinical pressure\n  \"load\": {\"pressure_mmhg\": 14} /* mmHg */\n}\n");
  EXPECT_EQ(load_scene(commented).load.pressure_mmhg, 14.0);
}

TEST(SceneFiles, DeepNestingAndHugeFilesAreRefusedBeforeParsing) {
  // 200,000 nested "[" (400 kB) once kept the parser busy for minutes with memory growing
  // quadratically: refused at once, naming the limit and where it was crossed. Brackets inside
  // strings and comments do not count, and a scene at the limit still reads as JSON.
  const auto t0 = std::chrono::steady_clock::now();
  const std::string deep = write_temp("deep.json", std::string(200000, '[') + std::string(200000, ']'));
  try {
    load_scene(deep);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_CONTAINS(e.what(), "deep.json: nests arrays and objects deeper than 64 levels (at line 1, column 65)");
  }
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 5.0);
  const std::string quoted = write_temp("quoted.json", "{\"name\": \"" + std::string(100, '[') + "\" /* " +
                                                           std::string(100, '{') + " */}\n// " + std::string(100, '[') + "\n");
  EXPECT_EQ(load_scene(quoted).name, std::string(100, '['));
  const std::string big = write_temp("big.json", "{\"name\": \"" + std::string(17u << 20, 'x') + "\"}");
  try {
    load_scene(big);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_CONTAINS(e.what(), "big.json: the scene file is " + std::to_string((17u << 20) + 12) + " bytes; at most 16777216 are read");
  }
}

TEST(SceneFiles, EverySceneInTheRepoLoads) {
  const fs::path dir = fs::path(PNEUMO_SOURCE_DIR) / "scenes";
  if (!fs::exists(dir)) GTEST_SKIP() << "no scenes/ folder yet";
  int loaded = 0;
  for (const auto& entry : fs::recursive_directory_iterator(dir)) {
    if (entry.path().extension() != ".json") continue;
    SCOPED_TRACE(entry.path().string());
    EXPECT_NO_THROW(load_scene(entry.path().string()));
    ++loaded;
  }
  if (loaded == 0) GTEST_SKIP() << "scenes/ holds no .json yet";
}

TEST(SceneReference, CommittedFileIsTheGeneratedOne) {
  const fs::path committed = fs::path(PNEUMO_SOURCE_DIR) / "docs" / "scene_reference.md";
  std::ifstream in(committed, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  const std::string generated = scene_reference_markdown();
  if (text.str() != generated) {
    const std::string fresh = write_temp("scene_reference.md", generated);
    FAIL() << committed.string() << " is stale (or missing). Regenerate it: "
           << "pneumo scene --reference > docs/scene_reference.md (the generated text is also in " << fresh << ")";
  }
}

TEST(SceneReference, ListsEveryKey) {
  const std::string md = scene_reference_markdown();
  for (const char* heading : {"## Top level", "## `load`", "## `render.cameras[]` (each item)",
                              "## `render.paths[].keyframes[]` (each item)", "## `material.label_young_kpa[]` (each item)"})
    EXPECT_CONTAINS(md, heading);
  for (const char* row : {"| `pressure_mmhg` | number | `12.0` | 0 to 100; 0 (rest) or at least 0.1 | mmHg |", "| `fov_deg` | number | `70.0` |",
                          "| `method` | enum | `\"newton\"` | \"static\", \"explicit\", \"newmark\", \"kitasaka2004\", \"newton\", "
                          "\"implicit-euler\" |"})
    EXPECT_CONTAINS(md, row);
}

}  // namespace
}  // namespace pneumo
