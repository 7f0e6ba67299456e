#include "pipeline/scene_stages.h"
#include "suite/bench_cases.h"

#include <chrono>
#include <filesystem>

#include <nlohmann/json.hpp>

#include "core/log.h"
#include "io/volume_io.h"
#include "scene/scene_presets.h"
#include "suite/bench_context.h"

namespace pneumo::bench {

namespace {

using Clock = std::chrono::steady_clock;

/// Quiets warnings for its lifetime (the phantom's scene lists TotalSegmentator ids its CT lacks: one warning
/// each, not news to a benchmark).
struct QuietLog {
  log::Level before = log::level();
  QuietLog() { log::set_level(log::Level::Quiet); }
  ~QuietLog() { log::set_level(before); }
};

void build_roles_and_mesh(BenchCase& c) {
  auto t0 = Clock::now();
  c.roles = assign_roles(c.scene, c.ct, c.labels ? &*c.labels : nullptr);
  c.seconds_roles = seconds_since(t0);
  remesh(c, cube_voxels_for(c.scene.mesh, c.roles.geometry));
}

}  // namespace

void remesh(BenchCase& c, const CubeVoxels& cube_voxels) {
  QuietLog quiet;
  c.scene.mesh.cube_voxels = cube_voxels;
  c.scene.mesh.cube_mm.reset();   // L in voxels here, whatever the scene said
  const auto t0 = Clock::now();
  c.mesh = build_scene_mesh(voxel_roles_of(c.roles), c.scene);
  c.seconds_mesh = seconds_since(t0);
}

BenchCase phantom_case(PhantomSize size, int cube_voxels) {
  QuietLog quiet;
  BenchCase c;
  c.name = phantom_size_name(size);
  c.scene = parse_scene(nlohmann::json::parse(phantom_scene_json(size)), "");
  use_nimura_springs(c.scene.material);   // the sections that take a phantom measure the springs
  if (cube_voxels > 0) c.scene.mesh.cube_voxels = cube_voxels;
  const auto t0 = Clock::now();
  Phantom ph = make_phantom(size);
  c.seconds_input = seconds_since(t0);
  c.ct = std::move(ph.ct);
  c.labels = std::move(ph.labels);
  build_roles_and_mesh(c);
  return c;
}

std::optional<BenchCase> scene_case(const std::string& scene_path, const std::string& name, std::string& why) {
  namespace fs = std::filesystem;
  if (scene_path.empty() || !fs::exists(scene_path)) {
    why = "scene " + (scene_path.empty() ? std::string("(none given)") : scene_path) + " not found";
    return std::nullopt;
  }
  BenchCase c;
  c.name = name;
  c.scene = load_scene(scene_path);
  if (c.scene.inputs.ct.empty() || !fs::exists(c.scene.inputs.ct)) {
    why = "the CT of " + scene_path + " (" + c.scene.inputs.ct + ") is not there (the repository's data/ folder)";
    return std::nullopt;
  }
  const auto t0 = Clock::now();
  c.ct = read_volume(c.scene.inputs.ct);
  if (!c.scene.inputs.labels.empty()) c.labels = read_volume(c.scene.inputs.labels);
  c.seconds_input = seconds_since(t0);
  build_roles_and_mesh(c);
  return c;
}

}  // namespace pneumo::bench
