#pragma once
// deformation.bin: the solved displacement of every mesh node, written by `pneumo simulate` and read
// by `pneumo warp` (and any later stage, or a resumed run, that needs the solved shape without the
// solver). The mesh itself is not stored: it is rebuilt deterministically from the scene, and a
// fingerprint of its rest positions and tetrahedra proves the rebuild is the mesh that was solved.
//
// Layout (little-endian, 64-byte header, then the payload):
//   0  char[8]  "PNEUMODF"          8  uint32 version (2)       12 uint32 header bytes (64)
//   16 uint64 node count            24 uint64 tetrahedron count  32 uint64 mesh fingerprint
//   40 uint64 payload checksum      48 float64 pressure (Pa)     56 uint32 flags (bit 0: converged)
//   60 uint32 zero
//   64 node count × 3 float64: displacement u = x − x_rest, metres, world RAS+ (node order of the mesh)
// Displacements rather than positions: a zero or uniform field stays exactly that (warp_mesh.h).
// Version 2 fingerprints the cube's voxels per axis (core/cube_voxels.h); version 1 fingerprinted one
// L for all three. A version 1 file is still read for a mesh of one L on every axis, the only meshes
// it could have been written for; for any other mesh it is refused as written for another mesh.
#include <cstdint>
#include <string>
#include <vector>

#include "mesh/mesh.h"

namespace pneumo {

struct Deformation {
  std::vector<Vec3> displacement_m;   // one per node
  double pressure_pa = 0.0;           // the pressure the solver reached
  bool converged = false;
};

/// The version write_deformation writes.
inline constexpr uint32_t kDeformationFileVersion = 2;

/// FNV-1a (64 bit) over the cube size, the rest positions' bits, node parts, tetrahedra and their
/// parts: equal for the same mesh built twice, different after any change to what it is made of.
/// As file `version` defines it: 2, the cube's voxels on each axis; 1, its one L (0 for a mesh whose
/// axes differ: read_deformation refuses every version 1 file for such a mesh).
uint64_t mesh_fingerprint(const Mesh& mesh, uint32_t version = kDeformationFileVersion);

/// Writes `path` atomically. std::invalid_argument when the field does not match the mesh's size.
void write_deformation(const std::string& path, const Mesh& mesh, const Deformation& d);

/// Reads `path` for `mesh`. InputError naming the file when it is missing, truncated, corrupt, of
/// another version, or was written for another mesh (the scene changed since the simulation).
Deformation read_deformation(const std::string& path, const Mesh& mesh);

}  // namespace pneumo
