#pragma once
// What a mesh must offer before any solver runs on it: something free to move, and no
// part the load would carry away as a rigid body. Both are properties of the case (its roles, its
// region of interest), not of the solver: they are refused as InputError, before the first step,
// with what to change, instead of a run that never converges or "diverges" with advice about Δt.
#include <string>

#include "mesh/mesh.h"
#include "solve/solver.h"

namespace pneumo {

/// The mesh's parts as connected by springs: part_of[node] is the index of its connected component.
struct MeshComponents {
  std::vector<int32_t> part_of;
  int32_t count = 0;
};
MeshComponents connected_components(const Mesh& m);

/// Throws InputError when every node is held on every axis (nothing can move), or when a connected
/// part of the mesh holds no node on an axis along which the load at rest (the larger of the start
/// and target pressures on its cavity faces, plus gravity) pushes it with a net force: a rigid
/// drift, for which no equilibrium exists. Only translations are checked: a part held at a single
/// point could still turn, but the lattice's fixed cubes hold four nodes or more wherever they
/// touch a part. Parts with no held node and no net load (a closed cavity, Lamé's sphere) pass.
/// The message starts with `what` (the scene file, or "mesh").
void check_solvable(const Mesh& m, const SolveOptions& opt, const std::string& what = "mesh");

}  // namespace pneumo
