#pragma once
// The mass-spring-damper mesh (method.md §3–4): nodes at cube corners of an L₀×L₁×L₂-voxel grid, 5
// tetrahedra per cube, springs and dampers on every tetrahedron edge, separate wall and viscera
// meshes (doubled where they touch), fixed nodes and the gas pressure's load.
//
// The geometry is resolved at the voxel, not the cube (docs/fidelity.md): a cube only says where
// nodes may be. Each tetrahedron's stiffness and mass are the share of its volume that its part's
// tissue fills (as the finite cell method weights cut cells), a node is held only where a fixed
// voxel touches it, and the pressure acts on the voxel faces between wall and viscera, each carried
// by the tetrahedron that holds it (an embedded surface). So the model converges as cubes shrink
// instead of thickening the wall and the fixed region by up to a cube.
//
// Units: positions in metres (world RAS+), masses in kg, stiffness in N/m, damping in N·s/m,
// volumes in m³. Interfaces convert to mm where users see them.
#include <array>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "core/cube_voxels.h"
#include "core/geometry.h"
#include "domain/types.h"

namespace pneumo {

enum class Part : uint8_t { Wall = 0, Viscera = 1 };
const char* part_name(Part p);

/// Bit mask of world axes a node is held on: 7 = fixed; single bits serve symmetry planes.
enum : uint8_t { kHoldX = 1, kHoldY = 2, kHoldZ = 4, kHoldAll = 7 };

/// The 6 edges of a tetrahedron as pairs of its local vertices.
inline constexpr int kTetEdges[6][2] = {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}};

/// What the mesh is built from: one role and one label per voxel on a grid.
struct VoxelRoles {
  Geometry geometry;
  const Role* role = nullptr;       // voxel_count() entries
  const uint16_t* label = nullptr;  // optional: organ labels for per-label Young's modulus
  const float* hu = nullptr;        // optional: the CT (HU), for moduli by tissue density (fat)
  /// The CT's own voxels within the grid, first and last index per axis (the rest is air padded
  /// around it); a last of -1 is the grid's last. Its faces are where the CT may cut the body
  /// (MeshOptions::cut_faces).
  Index3 ct_first{0, 0, 0}, ct_last{-1, -1, -1};
};

/// Young's modulus (Pa) of one voxel of tissue: its role, label (0 when none) and HU (0 without a CT).
using VoxelYoungFn = std::function<double(Role, int label, float hu)>;

/// Poisson's ratio of one voxel of tissue, from the same three (the lungs' ν by their density).
using VoxelPoissonFn = std::function<double(Role, int label, float hu)>;

/// The smallest share of a tetrahedron's volume counted as its tissue: tetrahedra of a meshed cube
/// that hold (almost) none of their part's tissue keep this fraction of its stiffness and mass, so
/// no node is left without stiffness or mass (the finite cell method's α). 10⁻² keeps such tetrahedra
/// from inverting next to bone thinner than a cube (10⁻³ left 263 on the demo phantom, 53 on the real CT
/// at 12 mm cubes) and moves the results by under 0.2 % (docs/fidelity.md).
inline constexpr double kMinTissueFraction = 1e-2;

struct MeshOptions {
  CubeVoxels cube_voxels{8};               // L per grid axis (core/cube_voxels.h)
  MeshModel model = MeshModel::WallViscera;
  std::optional<Vec3> roi_min_mm, roi_max_mm;   // cubes whose centre lies outside are not meshed
  /// What the caller will allocate per node and per tetrahedron once the mesh exists (a solver's
  /// state), counted in the memory estimate build_mesh checks before it allocates anything.
  uint64_t reserve_bytes_per_node = 0, reserve_bytes_per_tet = 0;
  /// Wall labels whose interface with the viscera stays closed (the retroperitoneal and
  /// extraperitoneal organs the viscera lie on): no gas pressure on those voxel faces, and their
  /// nodes marked in Mesh::node_attached for the bond of solve/interface_tie.h.
  std::vector<int> attached_labels;
  /// The faces where the CT cuts the body (a scan that stops at the liver or at L3, a field of view
  /// that cuts the flanks): Slide holds the nodes of the lattice plane nearest each cranial, caudal
  /// and lateral face of the CT's box (VoxelRoles::ct_first/ct_last) that cuts tissue on the face's
  /// normal (world z or x) and leaves them free within it, as a symmetry plane does: the body beyond is taken as the mirror image of the body
  /// inside, so the wall's cut edge neither lifts like a flap nor lets gas or viscera out
  /// (docs/fidelity.md, "Cut faces"). Free leaves them free, as a real edge of tissue would be, and
  /// is the default here: a mesh built from voxels that are no CT (a test block, a validation) has no
  /// cut; scenes default to Slide (SceneMesh::cut_faces).
  CutFaces cut_faces = CutFaces::Free;
  /// With Slide, the cranial cut face opens onto the chest: where the tissue the CT cuts there is
  /// viscera (the liver, the stomach under the dome), or wall for which this says true (the lungs),
  /// the face's nodes are not held on its normal but listed in Mesh::thorax_node, for the lungs beyond
  /// the cut (solve/thorax_beyond_cut.h), whose compliance the caller sets. Unset: every cut face slides.
  std::function<bool(Role, int label, float hu)> opens_onto_thorax;
  /// When set, each tetrahedron's ν (Mesh::tet_poisson) is the mean of its tissue's sample points'
  /// (one tissue: its own; lung and diaphragm in one tetrahedron: between the two). Unset: the
  /// caller fills tet_poisson.
  VoxelPoissonFn poisson_for;
};

struct Mesh;

/// What a mesh will hold, counted from the roles in two passes over the voxels without building it.
struct MeshFootprint {
  int64_t cubes = 0;           // lattice cubes, meshed or not (build_mesh's scratch covers them all)
  int64_t part_cubes = 0;      // cubes meshed, once per part that meshes them (5 tetrahedra each)
  int64_t nodes = 0;           // exact
  int64_t contact_faces = 0;   // voxel faces of the contact surfaces (ContactFaces' tissue faces)
  int64_t cavity_faces = 0;    // voxel faces between wall and viscera
  int64_t fixed_faces = 0;     // faces of bone towards neither bone nor wall (an upper bound)
  uint64_t bytes = 0;          // the peak build_mesh allocates, plus the reserve of MeshOptions
};
/// The estimate build_mesh checks against available_memory() (InputError, exit 2, with both figures).
MeshFootprint estimate_mesh_footprint(const VoxelRoles& roles, const MeshOptions& opt);
/// InputError (exit 2) when that estimate exceeds available_memory(), with both figures and the
/// smallest mesh.cube_voxels that fits.
void require_mesh_memory(const VoxelRoles& roles, const MeshOptions& opt);
/// The bytes a built mesh holds (its arrays' capacities): what the estimate must cover.
uint64_t mesh_bytes(const Mesh& m);

/// The surfaces the contact term keeps apart (solve/contact.h): the viscera's surface (every face of a
/// viscera voxel towards a voxel that is not viscera), the wall's side of the cavity (every face of a
/// wall voxel towards a viscera voxel) and the bone near the viscera (every face of a fixed voxel
/// towards neither bone nor wall, in or next to a cube the viscera mesh). A tissue face is a point embedded in the tetrahedron of its part that holds the face's centre
/// (barycentric weights w) with c = cof(D_m)⁻¹ N dA = D_mᵀ N dA / det D_m, so that cof(D_s)·c is its
/// deformed area vector out of its own tissue (Nanson, as the pressure loads). A fixed face does not
/// move: its centre and its area vector out of the bone. Metres and m².
struct ContactFaces {
  std::vector<int32_t> tet;
  std::vector<std::array<double, 4>> w;
  std::vector<Vec3> c;
  std::vector<Part> part;
  std::vector<Vec3> fixed_centre_m, fixed_area_m2;
  std::size_t size() const { return tet.size(); }
};

struct MeshStats {
  int64_t nodes = 0, tetrahedra = 0, springs = 0, fixed_nodes = 0;
  int64_t cut_face_nodes = 0;      // nodes held on cut faces' normals only (MeshOptions::cut_faces)
  int64_t thorax_nodes = 0;        // cranial cut-face nodes that open onto the chest (Mesh::thorax_node)
  int64_t cavity_faces = 0;        // voxel faces between wall and viscera, both sides counted
  int64_t attached_faces = 0;      // of those, the ones of an attached label (no gas), both sides
  int64_t pressure_tetrahedra = 0; // tetrahedra carrying some of them
  int64_t wall_cubes = 0, viscera_cubes = 0, doubled_cubes = 0;
  int64_t wall_nodes = 0, viscera_nodes = 0;
};

struct Mesh {
  // Nodes.
  std::vector<Vec3> rest_m;                 // rest position, metres
  std::vector<Part> node_part;
  std::vector<uint8_t> hold;                // kHold* mask
  std::vector<std::array<int32_t, 3>> node_lattice;   // lattice coordinates (cube corners)
  std::vector<uint8_t> node_attached;       // 1: a corner of a cube holding an attached face (MeshOptions)
  std::vector<double> mass_kg;              // §4: ρ Σ V_t / 4 (set by assign_material)

  // Tetrahedra (positively oriented at rest).
  std::vector<std::array<int32_t, 4>> tets;
  std::vector<Part> tet_part;
  std::vector<uint16_t> tet_label;          // dominant label of its part in its cube
  std::vector<double> tet_fraction;         // share of its volume its part's tissue fills (≥ kMinTissueFraction)
  std::vector<int64_t> tet_cube;            // linear cube index
  std::vector<double> tet_rest_volume_m3;
  std::vector<double> tet_young_pa;         // Hill's mean over its tissue × the tissue's share, floored
  std::vector<double> tet_poisson;          // ν of the finite elements (empty: 1/4, the springs' own)
  // The finite elements' fibre family (solve/fem_element.h; mesh/wall_fibres.h): each tetrahedron's unit
  // rest direction a₀ and k₁ (Pa; 0 or empty: none), and the one k₂. The springs ignore them.
  std::vector<Vec3> tet_fibre;
  std::vector<double> tet_fibre_k1_pa;
  double fibre_k2 = 0;
  std::vector<std::array<int32_t, 6>> tet_springs;   // spring of each local edge (kTetEdges order)

  // Springs (one per unique tetrahedron edge, per part).
  std::vector<std::array<int32_t, 2>> springs;
  std::vector<double> spring_rest_m;
  std::vector<double> spring_k;             // N/m, §4: Σ over tetrahedra sharing the edge
  std::vector<double> spring_c;             // N·s/m, §4: 2ζ√(m k)

  // Gas pressure (§5) on the voxel faces between wall and viscera tissue, embedded in the
  // tetrahedra that hold them. Load l sits on tetrahedron load_tet[l]; with B_i = Σ_faces w_i N dA
  // (w_i the face's barycentric weight of vertex i, N dA its rest area vector out of its own
  // solid, m²) and D_m the rest edge matrix, load_c[l][i] = D_mᵀ B_i / det D_m. Nanson's formula
  // (n da = cof F · N dA, F = D_s D_m⁻¹) then gives the follower force on vertex i as
  // f_i = −P · cof(D_s) · c_i (pressure_load_forces): exact for flat faces under the tetrahedron's
  // affine map. A face of the tetrahedron itself is the special case of the old cavity triangles.
  std::vector<int32_t> load_tet;
  std::vector<std::array<Vec3, 4>> load_c;
  ContactFaces contact;
  // The cranial cut face where it opens onto the chest (MeshOptions::opens_onto_thorax): its nodes and
  // each one's share of the face as an area vector out of the mesh, towards the head (m²), so that
  // Σ thorax_area_m2[i]·u_i is the volume the face pushes into the chest (solve/thorax_beyond_cut.h).
  std::vector<int32_t> thorax_node;
  std::vector<Vec3> thorax_area_m2;
  double thorax_compliance_m3_per_pa = 0;   // the lungs' beyond the cut; 0: the face is held (set by the caller)

  // Where it came from.
  Geometry grid;                            // the voxel grid
  CubeVoxels cube_voxels{0};                // L per grid axis
  std::array<int64_t, 3> cubes{0, 0, 0};    // cubes per axis
  MeshStats stats;

  int64_t node_count() const { return int64_t(rest_m.size()); }
};

/// Builds the mesh from voxel roles (§3). Throws InputError when nothing would be meshed.
/// Young's modulus per tetrahedron is the average of `young_pa_for(role, label, hu)` over its points
/// (0 where they hold no tissue of its part).
Mesh build_mesh(const VoxelRoles& roles, const MeshOptions& opt, const VoxelYoungFn& young_pa_for);
/// The same with a modulus by role and label only.
Mesh build_mesh(const VoxelRoles& roles, const MeshOptions& opt, const std::function<double(Role, int)>& young_pa_for);

/// u = x − x₀ per node (metres): what deformation.bin, checkpoints and the warp carry.
std::vector<Vec3> displacements(const Mesh& m, const std::vector<Vec3>& x);

/// The same mesh with rest shape `rest_m` (one position per node, metres): the springs' rest lengths and the
/// tetrahedra's rest volumes follow it; the material (masses, stiffnesses, dampers, moduli) and the
/// embedded faces stay. An embedded face keeps its barycentric weights and its c = cof(D_m)⁻¹ N dA,
/// which is the face's area vector in the tetrahedron's own frame, the same in every rest shape the
/// tissue maps to (Nanson). Throws std::runtime_error when a tetrahedron would be inside out.
Mesh with_rest_shape(const Mesh& m, const std::vector<Vec3>& rest_m);

struct MaterialOptions {
  double density_kg_m3 = 1096.0;
  double damping_ratio = 0.4;
  double spring_scale = 1.0;
};
/// Masses, spring stiffnesses (Lloyd) and dampers (§4), from the tetrahedra's volumes and moduli.
void assign_material(Mesh& mesh, const MaterialOptions& opt);

/// Lloyd's per-tetrahedron spring constant for ν = 1/4 (§4): (2√2/25)·E·(6√2·V)^(1/3), N/m.
double lloyd_tet_spring_k(double young_pa, double volume_m3);
/// Each node's own stiffness (N/m): Σ over its tetrahedra of Lloyd's k for their modulus and rest volume.
std::vector<double> node_lloyd_stiffness(const Mesh& m);

/// The 4 vertex forces of pressure load l at positions x (§5): f_i = −P · cof(D_s) · c_i.
std::array<Vec3, 4> pressure_load_forces(const Mesh& m, int64_t l, const std::vector<Vec3>& x, double pressure_pa);
/// The gas volume the cavity faces enclose at positions x (m³), by the divergence theorem with a
/// field F of divergence 1: −Σ_faces F(x_f) · n da. Exact for a closed surface whatever the field.
/// Without `cut_normal`, F = ⅓(x − origin) (a point near the faces keeps an open rim's share small).
/// With the unit normal of the planes where the CT's field of view cuts the cavity off (its axial
/// slices), F = ½(I − n nᵀ)(x − origin): the field lies in those planes, so the missing caps there
/// carry no flux and a cavity open only at the CT's cut ends is measured exactly.
double enclosed_cavity_volume(const Mesh& m, const std::vector<Vec3>& x, const Vec3& origin,
                              const std::optional<Vec3>& cut_normal = std::nullopt);
/// The pressure's nodal forces at positions x (one entry per node).
std::vector<Vec3> pressure_forces(const Mesh& m, const std::vector<Vec3>& x, double pressure_pa);

/// cof(D_s)·c for a tetrahedron's edges e_k = x_k − x_0: c.x (e2×e3) + c.y (e3×e1) + c.z (e1×e2), the
/// deformed area vector of an embedded face with c = cof(D_m)⁻¹ N dA (Nanson; the pressure loads and
/// the contact faces).
inline Vec3 cofactor_times(const Vec3& e1, const Vec3& e2, const Vec3& e3, const Vec3& c) {
  return c[0] * e2.cross(e3) + c[1] * e3.cross(e1) + c[2] * e1.cross(e2);
}

/// Signed volume of the tetrahedron (a,b,c,d), positive when (b−a, c−a, d−a) is right-handed.
inline double signed_tet_volume(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
  return (b - a).cross(c - a).dot(d - a) / 6.0;
}

}  // namespace pneumo
