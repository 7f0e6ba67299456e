#pragma once
// The one place a scene becomes what each stage takes: the stages (roles, mesh, solve) know their
// own options and nothing of the scene file (the build enforces it: cmake/Layers.cmake); these
// read a scene's sections, convert units to the stages' (SI inside), and call them.
#include <optional>

#include "io/volume.h"
#include "mesh/mesh.h"
#include "roles/roles.h"
#include "scene/scene.h"
#include "solve/solver.h"

namespace pneumo {

/// roles.* and the inputs' names for messages, then assign_roles (roles/roles.h).
RoleVolume assign_roles(const Scene& scene, const Volume& ct, const Volume* labels);

/// Reads inputs.ct (and inputs.labels when given), then assign_roles. With `inputs`, the volumes
/// read are handed back there (what a run's warp reads again otherwise).
struct InputVolumes {
  std::optional<Volume> ct, labels;
};
RoleVolume load_roles(const Scene& scene, InputVolumes* inputs = nullptr);

/// What the mesh is built from on a case's working grid: its roles, labels and HU, and where the CT
/// lies within the padding (its faces are the cut faces, MeshOptions::cut_faces).
VoxelRoles voxel_roles_of(const RoleVolume& roles);

/// The mesh of a case: mesh.* (the cube size from the CT's spacing when mesh.cube_mm is set),
/// material.* per role, label and HU (Scene::young_kpa_for, poisson_for), masses and springs. With
/// `to_solve` the memory estimate checked before building counts the solver's state too.
Mesh build_scene_mesh(const VoxelRoles& roles, const Scene& scene, bool to_solve = false);

/// The options a scene asks for (units converted to SI).
SolveOptions solve_options_from_scene(const Scene& scene);

}  // namespace pneumo
