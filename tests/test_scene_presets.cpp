// Scene presets (host/scene/scene_presets.h): "preset" supplies mesh.cube_mm, solver.method and
// solver.residual_tolerance; the scene's own keys win; cube_mm becomes L from the CT's coarsest spacing; the echo
// of a preset scene parses back to the same scene. Exact comparisons: these are values copied, not computed.
#include <gtest/gtest.h>

#include "scene/scene.h"
#include "scene/scene_presets.h"

using namespace pneumo;
using json = nlohmann::json;

namespace {
const std::string kOrigin = "presets_test.json";
}

TEST(ScenePresets, EachPresetSetsItsSettings) {
  for (const ScenePreset p : {ScenePreset::Preview, ScenePreset::Balanced, ScenePreset::Accurate}) {
    SCOPED_TRACE(enum_name(p));
    const Scene s = parse_scene(json{{"preset", enum_name(p)}}, kOrigin);
    const PresetSettings& want = preset_settings(p);
    EXPECT_EQ(s.preset, p);
    ASSERT_TRUE(s.mesh.cube_mm.has_value());
    EXPECT_EQ(*s.mesh.cube_mm, want.cube_mm);
    // The default model, the finite elements, takes the preset's solver for them: Newton.
    EXPECT_EQ(s.solver.method, preset_method(want, s.material.model));
    EXPECT_EQ(s.solver.method, SolverMethod::Newton);
    EXPECT_EQ(s.solver.residual_tolerance, want.residual_tolerance);
  }
}

TEST(ScenePresets, TheScenesOwnKeysWin) {
  const Scene s = parse_scene(json{{"preset", "preview"}, {"solver", {{"residual_tolerance", 0.5}}},
                                   {"mesh", {{"cube_mm", 7.0}}}},
                              kOrigin);
  EXPECT_EQ(s.solver.residual_tolerance, 0.5);
  EXPECT_EQ(*s.mesh.cube_mm, 7.0);
  EXPECT_EQ(s.solver.method, preset_settings(ScenePreset::Preview).fem_method);
}

TEST(ScenePresets, ANullTheSceneGivesStillSwitchesItsDefaultOff) {
  // A preset fills only the keys the scene lacks: a null the scene gives (how a default is switched off) must
  // survive, not be dropped as RFC 7386 drops nulls when a patch is merged.
  const Scene s = parse_scene(json{{"preset", "preview"}, {"material", {{"viscera_young_kpa", nullptr},
                                                                         {"fat_young_kpa", nullptr}}}},
                              kOrigin);
  EXPECT_FALSE(s.material.viscera_young_kpa.has_value());
  EXPECT_FALSE(s.material.fat_young_kpa.has_value());
  EXPECT_EQ(*s.mesh.cube_mm, preset_settings(ScenePreset::Preview).cube_mm);
}

TEST(ScenePresets, NoneAndAbsentLeaveTheDefaults) {
  const Scene none = parse_scene(json{{"preset", "none"}}, kOrigin), absent = parse_scene(json::object(), kOrigin);
  EXPECT_EQ(none.echo(), absent.echo());
  EXPECT_FALSE(absent.mesh.cube_mm.has_value());
}

TEST(ScenePresets, UnknownPresetIsRefusedNamingTheChoices) {
  try {
    parse_scene(json{{"preset", "fast"}}, kOrigin);
    FAIL() << "accepted";
  } catch (const std::exception& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("preset"), std::string::npos) << m;
    EXPECT_NE(m.find("balanced"), std::string::npos) << m;
  }
}

TEST(ScenePresets, EchoParsesBackToTheSameScene) {
  const Scene s = parse_scene(json{{"preset", "accurate"}}, kOrigin);
  EXPECT_EQ(parse_scene(s.echo(), kOrigin).echo(), s.echo());
}

TEST(ScenePresets, CubeMmGivesTheNearestWholeVoxelsAlongEachAxis) {
  Geometry g;
  g.dims = {10, 10, 10};
  g.spacing_mm = Vec3(0.75, 0.75, 1.5);
  SceneMesh m;
  m.cube_voxels = 5;
  EXPECT_EQ(cube_voxels_for(m, g), 5);   // unset: cube_voxels
  m.cube_mm = 9.0;
  EXPECT_EQ(cube_voxels_for(m, g), CubeVoxels(12, 12, 6));   // 9 mm on every axis (by the coarsest: 4.5 × 4.5 × 9)
  m.cube_mm = 0.2;
  EXPECT_EQ(cube_voxels_for(m, g), 1);   // at least one voxel
}

TEST(ScenePresets, TheFiniteElementsTakeNewtonAtEveryPreset) {
  // The springs keep each preset's measured solver; the finite elements take Newton, where the static
  // solver did not finish or diverged on the real CT (scene_presets.cpp). A solver the scene names wins.
  for (const ScenePreset p : {ScenePreset::Preview, ScenePreset::Balanced, ScenePreset::Accurate}) {
    SCOPED_TRACE(enum_name(p));
    for (const char* model : {"fem-corotational", "fem-neohookean"}) {
      const Scene s = parse_scene(json{{"preset", enum_name(p)}, {"material", {{"model", model}}}}, kOrigin);
      EXPECT_EQ(s.solver.method, SolverMethod::Newton) << model;
      EXPECT_EQ(*s.mesh.cube_mm, preset_settings(p).cube_mm);
    }
    const Scene springs = parse_scene(json{{"preset", enum_name(p)}, {"material", {{"model", "msd"}}}}, kOrigin);
    EXPECT_EQ(springs.solver.method, preset_settings(p).method);
    const Scene told = parse_scene(
        json{{"preset", enum_name(p)}, {"material", {{"model", "fem-neohookean"}}}, {"solver", {{"method", "static"}}}},
        kOrigin);
    EXPECT_EQ(told.solver.method, SolverMethod::Static);
  }
}
