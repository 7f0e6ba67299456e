#pragma once
// The mesh as the image warp sees it (method.md §7): tetrahedra with their rest and deformed node
// positions in the continuous voxel-index coordinates of the working grid (the roles' grid, padding
// included), and which lattice cubes the meshes filled at rest.
//
// Index coordinates: voxel (i,j,k)'s centre is the point (i,j,k); a cube of L_x voxels on axis x spans
// [aL_x − ½, (a+1)L_x − ½) there (mesh_build.cpp's node placement), L per axis (core/cube_voxels.h). Working there turns world
// geometry (spacing, origin, an oblique or flipped direction) into plain arithmetic once, on the
// host, in double precision.
//
// The deformation is carried as displacements, not positions: a uniform displacement gives every
// node bit-identical index displacements, so a translation by whole voxels stays exactly whole
// (the warp's exactness tests rely on it), and rounding never mixes the node's absolute position
// (hundreds of voxels) into the small quantity that moves it.
#include <array>
#include <cstdint>
#include <vector>

#include "core/geometry.h"
#include "mesh/mesh.h"
#include "roles/pad.h"

namespace pneumo {

struct WarpMesh {
  Geometry grid;                                  // the working grid the indices refer to
  std::vector<Vec3> rest_ijk;                     // rest node positions, index coordinates
  std::vector<Vec3> disp_ijk;                     // node displacements, index units
  std::vector<std::array<int32_t, 4>> tets;
  std::vector<Part> tet_part;
  // Rest space: the lattice cubes holding any tetrahedron; a voxel lies in it iff its cube does.
  CubeVoxels cube_voxels{0};
  std::array<int64_t, 3> cubes{0, 0, 0};
  std::vector<uint8_t> cube_meshed;               // cubes[0]·cubes[1]·cubes[2], a fastest

  int64_t tet_count() const { return int64_t(tets.size()); }
  Vec3 deformed_ijk(int32_t node) const { return rest_ijk[node] + disp_ijk[node]; }
  /// Whether working-grid voxel (i,j,k) lies in a cube the meshes filled at rest. Inline: rule 5
  /// (cavity_enclosure.h) asks it for most of 10⁸ voxels.
  bool in_rest_space(int64_t i, int64_t j, int64_t k) const {
    if (i < 0 || j < 0 || k < 0) return false;
    const int64_t a = i / cube_voxels[0], b = j / cube_voxels[1], c = k / cube_voxels[2];
    if (a >= cubes[0] || b >= cubes[1] || c >= cubes[2]) return false;
    return cube_meshed[std::size_t(a + cubes[0] * (b + cubes[1] * c))] != 0;
  }
};

/// Throws std::invalid_argument naming the first thing `m` gets wrong of what both warps index by without checks:
/// sizes (a part per tetrahedron, a displacement per node), node ids in range, and a rest-space table covering the
/// grid (ceil(dims / cube_voxels) cubes per axis at least). make_warp_mesh's meshes always pass; hand-built ones
/// (the peers' case in bench/) are checked at the warp's door.
void check_warp_mesh(const WarpMesh& m);

/// The warp mesh of `mesh` displaced by `displacement_m` (metres, one per node, world RAS+).
/// std::invalid_argument when the sizes differ.
WarpMesh make_warp_mesh(const Mesh& mesh, const std::vector<Vec3>& displacement_m);

/// How much to grow m.grid so that every deformed node lies in one of its voxels' cells: the output
/// grid of a body that moved out of the CT. Whole cubes at the low
/// ends (of that axis's L), so that cube a keeps its place [aL − ½, (a+1)L − ½) in the lattice after the shift; single
/// voxels at the high ends; nothing on a side the nodes stay inside. No end grows by more than
/// `max_voxels` on its axis (rounded down to whole cubes at the low ends): a node flung far by a
/// diverged solve must not ask for gigabytes. Non-finite positions are skipped.
PadVoxels growth_to_hold_deformed(const WarpMesh& m, const Index3& max_voxels);

/// `m` on its grid grown by `grow` (padded_geometry): index coordinates shifted by grow.lo and the
/// rest-space table re-indexed, so the warp of the grown roles equals the warp of the original on
/// their common voxels. std::invalid_argument unless grow.lo is whole cubes and no end shrinks.
WarpMesh grown_warp_mesh(const WarpMesh& m, const PadVoxels& grow);

/// The same deformation on another grid: `m`'s nodes and displacements in `target`'s index
/// coordinates (through world mm), and its rest space as a table of `target`'s single voxels
/// (cube_voxels 1): a voxel lies in it when its centre lies in a cube `m`'s meshes filled. One solve's
/// deformation applied to the same body imaged at another resolution (`pneumo validate
/// view-resolution`); on `m.grid` itself the warp is unchanged.
WarpMesh warp_mesh_on_grid(const WarpMesh& m, const Geometry& target);

/// A deformed tetrahedron too flat to invert (|det| of its edge matrix below 1e-9 of its edge
/// length cubed): it covers no voxel centre in a way that could be sampled. Both the reference and
/// the device skip exactly the tetrahedra this names, so they never disagree about them.
bool warp_tet_degenerate(const WarpMesh& m, int64_t tet);

/// The containment tolerance on barycentric weights: a voxel centre belongs to a tetrahedron when
/// every weight is ≥ −kWarpTolerance. Voxel centres lie exactly on the lattice's face diagonals,
/// and rounding may put one a few 1e-7 outside both tetrahedra sharing a face; 1e-4 covers that
/// with room, and extrapolates the map by at most 1e-4 of an edge (1e-3 voxel for L = 8).
constexpr double kWarpTolerance = 1e-4;

}  // namespace pneumo
