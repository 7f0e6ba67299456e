#pragma once
// A whole case small enough to simulate in well under a second: a CT, its label map and a scene,
// written into a folder. 16×16×10 voxels of 5 mm: a fixed back (two layers), viscera above it, a
// wall slab on top held by a fixed rim, air above; cubes of 2 voxels. Tests spoil one piece at a
// time (a header, a voxel, a key) and run `pneumo` on it.
#include <cstdint>
#include <string>

#include <nlohmann/json.hpp>

#include "io/volume_io.h"
#include "io_test_support.h"

namespace pneumo::testing_support {

enum TinyLabel : uint8_t { kTinyAir = 0, kTinyWall = 1, kTinyViscera = 2, kTinyFixed = 3 };

inline Geometry tiny_case_grid() {
  Geometry g;
  g.dims = {16, 16, 10};
  g.spacing_mm = Vec3::Constant(5.0);
  g.origin_mm = Vec3(-40.0, -40.0, 100.0);
  return g;
}

/// The label of voxel (i, j, k): k is the anterior axis here only in the sense of "up the stack";
/// the roles come from the labels, so orientation does not matter to the tests that use this.
inline uint8_t tiny_case_label(int64_t i, int64_t j, int64_t k) {
  const bool rim = i < 2 || j < 2 || i > 13 || j > 13;
  if (k < 2) return kTinyFixed;
  if (k < 6) return rim ? kTinyFixed : kTinyViscera;
  if (k < 8) return rim ? kTinyFixed : kTinyWall;
  return kTinyAir;
}

inline Volume tiny_case_labels() {
  const Geometry g = tiny_case_grid();
  Volume v(g, VoxelType::UInt8);
  for (int64_t k = 0; k < g.dims[2]; ++k)
    for (int64_t j = 0; j < g.dims[1]; ++j)
      for (int64_t i = 0; i < g.dims[0]; ++i) v.data<uint8_t>()[g.linear_index(i, j, k)] = tiny_case_label(i, j, k);
  return v;
}

/// Float32 HU: air -1000, soft tissue 40, bone 700 (the fixed labels).
inline Volume tiny_case_ct() {
  const Geometry g = tiny_case_grid();
  const Volume labels = tiny_case_labels();
  Volume v(g, VoxelType::Float32);
  for (int64_t n = 0; n < g.voxel_count(); ++n) {
    const uint8_t l = labels.data<uint8_t>()[n];
    v.data<float>()[n] = l == kTinyAir ? -1000.0f : l == kTinyFixed ? 700.0f : 40.0f;
  }
  return v;
}

inline nlohmann::json tiny_case_scene_json() {
  return nlohmann::json{
      {"name", "tiny"},
      {"inputs", {{"ct", "ct.nii.gz"}, {"labels", "labels.nii.gz"}}},
      {"roles",
       {{"source", "labels"}, {"wall_labels", {1}}, {"viscera_labels", {2}}, {"fixed_labels", {3}}}},
      {"mesh", {{"cube_voxels", 2}}},
      {"load", {{"pressure_mmhg", 12}}},
      {"render", {{"width", 32}, {"height", 24}}}};   // the exterior views only, small: `pneumo run` in seconds
}

/// Writes ct.nii.gz, labels.nii.gz and scene.json (from `scene`) into `dir`; returns the scene's path.
inline std::string write_tiny_case(const ScratchDir& dir, const nlohmann::json& scene = tiny_case_scene_json(),
                                   const Volume& ct = tiny_case_ct(), const Volume& labels = tiny_case_labels()) {
  write_volume(ct, dir.file("ct.nii.gz"));
  write_volume(labels, dir.file("labels.nii.gz"));
  const std::string path = dir.file("scene.json");
  write_bytes(path, scene.dump(2) + "\n");
  return path;
}

}  // namespace pneumo::testing_support
