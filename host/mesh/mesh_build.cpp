// Builds the cube/tetrahedron mesh from voxel roles (method.md §3).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "core/error.h"
#include "core/memory_budget.h"
#include "core/units.h"
#include "domain/label_set.h"
#include "mesh/cube_lattice.h"
#include "mesh/mesh.h"

namespace pneumo {

const char* part_name(Part p) { return p == Part::Wall ? "wall" : "viscera"; }

std::vector<Vec3> displacements(const Mesh& m, const std::vector<Vec3>& x) {
  std::vector<Vec3> u(x.size());
  for (std::size_t n = 0; n < x.size(); ++n) u[n] = x[n] - m.rest_m[n];
  return u;
}

namespace {

constexpr int kParts = 2;

struct Lattice {
  std::array<int64_t, 3> cubes{};
  int64_t cube_index(int64_t a, int64_t b, int64_t c) const { return a + cubes[0] * (b + cubes[1] * c); }
  int64_t node_index(int64_t a, int64_t b, int64_t c) const {
    return a + (cubes[0] + 1) * (b + (cubes[1] + 1) * c);
  }
  int64_t node_count() const { return (cubes[0] + 1) * (cubes[1] + 1) * (cubes[2] + 1); }
  bool inside(int64_t a, int64_t b, int64_t c) const {
    return a >= 0 && b >= 0 && c >= 0 && a < cubes[0] && b < cubes[1] && c < cubes[2];
  }
};

/// Sample points per voxel along an axis of L voxels per cube: at least 4 per cube edge, so that even
/// with 1-voxel cubes each corner tetrahedron (a sixth of the cube) holds several. With N_a = s_a·L_a
/// samples along axis a at u_a = (2m + 1)/(2N_a), Σ|u − o| = 1 needs Σ (2m_a + 1)·D/(2N_a) = D for
/// D = lcm(2N_a): when every N_a holds the same power of 2 (an isotropic lattice, or (12, 12, 4)) the
/// left side is a sum of three odd numbers and D is even, so no sample lies on a tetrahedron's face.
/// Otherwise a few may, and tet_holding gives each to one tetrahedron (rounding decides which) the same
/// way in every cube of its pattern and in that pattern's per_tet, so a full tetrahedron still counts as full.
int samples_per_voxel(int L) { return std::max(1, (4 + L - 1) / L); }

/// Per cube: which roles its voxels hold, each part's dominant label, and per part and tetrahedron
/// (cube_tets order) how many sample points hold the part's tissue, the sum of their moduli and the
/// sum of their compliances (1/E), for the Voigt and Reuss bounds of the tetrahedron's modulus.
struct CubeContent {
  bool has[4] = {false, false, false, false};   // indexed by Role
  uint16_t label[kParts] = {0, 0};
  int32_t tissue[kParts][5] = {{0, 0, 0, 0, 0}, {0, 0, 0, 0, 0}};
  double young_sum[kParts][5] = {{0, 0, 0, 0, 0}, {0, 0, 0, 0, 0}};
  double compliance_sum[kParts][5] = {{0, 0, 0, 0, 0}, {0, 0, 0, 0, 0}};
  double poisson_sum[kParts][5] = {{0, 0, 0, 0, 0}, {0, 0, 0, 0, 0}};   // with MeshOptions::poisson_for
};

/// Which tetrahedron holds each sample point of a cube, for both patterns: the same in every cube, so
/// found once per mesh, not for each of 10⁸ voxels. Entry ((z·L₁ + y)·L₀ + x)·s³ + (mz·s₁ + my)·s₀ + mx
/// (s³ = s₀s₁s₂): voxel (x,y,z) of the cube, its sample (mx,my,mz) at ((x + (mx + ½)/s₀) / L₀, …).
struct SampleTets {
  CubeVoxels L{1};
  std::array<int, 3> s{1, 1, 1};
  int s3 = 1;
  std::vector<uint8_t> tet_of[2];   // [odd pattern]

  explicit SampleTets(const CubeVoxels& cube)
      : L(cube), s{samples_per_voxel(cube[0]), samples_per_voxel(cube[1]), samples_per_voxel(cube[2])},
        s3(s[0] * s[1] * s[2]) {
    for (int odd = 0; odd < 2; ++odd) {
      tet_of[odd].resize(std::size_t(L.volume()) * s3);
      for (int z = 0; z < L[2]; ++z)
        for (int y = 0; y < L[1]; ++y)
          for (int x = 0; x < L[0]; ++x)
            for (int mz = 0; mz < s[2]; ++mz)
              for (int my = 0; my < s[1]; ++my)
                for (int mx = 0; mx < s[0]; ++mx) {
                  const std::array<double, 3> u{(double(x) + (mx + 0.5) / s[0]) / L[0],
                                                (double(y) + (my + 0.5) / s[1]) / L[1],
                                                (double(z) + (mz + 0.5) / s[2]) / L[2]};
                  tet_of[odd][std::size_t(((z * L[1] + y) * L[0] + x) * s3 + (mz * s[1] + my) * s[0] + mx)] =
                      uint8_t(lattice::tet_holding(u, odd != 0));
                }
    }
  }
  /// The sample points of a whole cube of pattern `odd` in each tetrahedron: the same for both patterns
  /// by symmetry where no sample lies on a face, counted per pattern for the samples rounding decides.
  std::array<int64_t, 5> per_tet(int odd) const {
    std::array<int64_t, 5> count{};
    for (uint8_t t : tet_of[odd]) ++count[t];
    return count;
  }
};

std::vector<CubeContent> classify_cubes(const VoxelRoles& roles, const Lattice& lat, const SampleTets& samples,
                                        const VoxelYoungFn& young_pa_for, const VoxelPoissonFn& poisson_for) {
  const Geometry& g = roles.geometry;
  const CubeVoxels& L = samples.L;
  const int s3 = samples.s3;
  const std::vector<uint8_t>(&tet_of)[2] = samples.tet_of;
  std::vector<CubeContent> out(lat.cubes[0] * lat.cubes[1] * lat.cubes[2]);
#pragma omp parallel
  {
    // Voxels per label, per part, in the cube at hand: a cube holds a few labels.
    std::vector<std::pair<uint16_t, int>> counts[kParts];
#pragma omp for schedule(dynamic) collapse(2)
    for (int64_t c = 0; c < lat.cubes[2]; ++c)
      for (int64_t b = 0; b < lat.cubes[1]; ++b)
        for (int64_t a = 0; a < lat.cubes[0]; ++a) {
          CubeContent cc;
          const int odd = ((a + b + c) & 1) != 0;
          for (auto& n : counts) n.clear();
          for (int64_t k = c * L[2]; k < std::min<int64_t>((c + 1) * L[2], g.dims[2]); ++k)
            for (int64_t j = b * L[1]; j < std::min<int64_t>((b + 1) * L[1], g.dims[1]); ++j)
              for (int64_t i = a * L[0]; i < std::min<int64_t>((a + 1) * L[0], g.dims[0]); ++i) {
                const int64_t v = g.linear_index(i, j, k);
                const Role r = roles.role[v];
                cc.has[static_cast<int>(r)] = true;
                if (r != Role::Wall && r != Role::Viscera) continue;
                const int p = r == Role::Wall ? 0 : 1;
                const uint16_t id = roles.label ? roles.label[v] : 0;
                auto hit = std::find_if(counts[p].begin(), counts[p].end(), [&](const auto& e) { return e.first == id; });
                if (hit == counts[p].end()) counts[p].emplace_back(id, 1);
                else ++hit->second;
                const float hu = roles.hu ? roles.hu[v] : 0.0f;
                const double young = young_pa_for(r, id, hu), compliance = 1.0 / young;
                const double nu = poisson_for ? poisson_for(r, id, hu) : 0.0;
                const uint8_t* tet =
                    tet_of[odd].data() + ((((k - c * L[2]) * L[1] + (j - b * L[1])) * L[0] + (i - a * L[0])) * s3);
                for (int m = 0; m < s3; ++m) {
                  ++cc.tissue[p][tet[m]];
                  cc.young_sum[p][tet[m]] += young;
                  cc.compliance_sum[p][tet[m]] += compliance;
                  cc.poisson_sum[p][tet[m]] += nu;
                }
              }
          // The most frequent label; on a tie the lowest id.
          for (int p = 0; p < kParts; ++p) {
            int best = -1;
            for (auto [id, n] : counts[p])
              if (n > best || (n == best && id < cc.label[p])) { best = n; cc.label[p] = id; }
          }
          out[lat.cube_index(a, b, c)] = cc;
        }
  }
  return out;
}

/// The modulus of a tetrahedron's tissue from its `n` samples (Σ E and Σ 1/E): Hill's estimate
/// (Hill 1952), the mean of the Voigt bound (equal strain, the arithmetic mean: layers in parallel)
/// and the Reuss bound (equal stress, the harmonic mean: layers in series). A linear tetrahedron
/// straddling fat (3 kPa) and muscle (60 kPa) cannot strain more in the fat than in the muscle, so
/// the Voigt mean alone made mixed tetrahedra too stiff: on the real CT the rise grew 7.3 % from
/// 6 to 3 mm cubes (43.4 -> 46.6 mm), where no tetrahedron mixes. With Hill's mean it falls
/// monotonically towards the same 3 mm answer (docs/fidelity.md §4). For one tissue the three agree.
/// Anything else in the tetrahedron (air, bone, the other part) counts as empty: the caller scales
/// by the tissue's share, as the finite cell method does.
double hill_modulus(double young_sum, double compliance_sum, int64_t n) {
  if (n <= 0) return 0.0;
  return 0.5 * (young_sum / double(n) + double(n) / compliance_sum);
}

/// Rest position of lattice node (a,b,c): the corner of voxel (aL₀, bL₁, cL₂) at index aL₀ − ½.
Vec3 node_world_m(const Geometry& g, int64_t a, int64_t b, int64_t c, const CubeVoxels& L) {
  const Vec3 idx(double(a * L[0]) - 0.5, double(b * L[1]) - 0.5, double(c * L[2]) - 0.5);
  return g.to_world(idx) * units::kMetresPerMm;
}

/// Whether a fixed voxel touches the lattice node (a,b,c): one of the 8 voxels sharing its corner.
bool touches_fixed(const VoxelRoles& roles, int64_t a, int64_t b, int64_t c, const CubeVoxels& L) {
  const Geometry& g = roles.geometry;
  for (int64_t k = c * L[2] - 1; k <= c * L[2]; ++k)
    for (int64_t j = b * L[1] - 1; j <= b * L[1]; ++j)
      for (int64_t i = a * L[0] - 1; i <= a * L[0]; ++i) {
        if (i < 0 || j < 0 || k < 0 || i >= g.dims[0] || j >= g.dims[1] || k >= g.dims[2]) continue;
        if (roles.role[g.linear_index(i, j, k)] == Role::Fixed) return true;
      }
  return false;
}

/// The hold bit of the world axis grid axis `a` runs along, or 0 where it leans from every world axis
/// by more than 1° (a tilted gantry): a node's holds are world axes, so a face oblique to them cannot
/// be held on its normal alone, and stays free.
uint8_t world_hold_of(const Geometry& g, int a) {
  int w = 0;
  for (int r = 1; r < 3; ++r)
    if (std::abs(g.direction(r, a)) > std::abs(g.direction(w, a))) w = r;
  return std::abs(g.direction(w, a)) >= std::cos(1.0 * 3.14159265358979323846 / 180.0) ? uint8_t(1 << w) : 0;
}

/// Whether the CT's boundary slice `slice` along `axis` holds tissue the mesh meshes (wall, and viscera
/// with `viscera`) in the cubes around the lattice node `n`: the CT cuts the body there.
bool cut_through_tissue(const VoxelRoles& roles, const std::array<int64_t, 3>& n, int axis, int64_t slice,
                        const CubeVoxels& L, bool viscera) {
  const Geometry& g = roles.geometry;
  const int u = (axis + 1) % 3, w = (axis + 2) % 3;
  std::array<int64_t, 3> v{};
  v[axis] = slice;
  for (v[w] = std::max<int64_t>(0, (n[w] - 1) * L[w]); v[w] < std::min(g.dims[w], (n[w] + 1) * L[w]); ++v[w])
    for (v[u] = std::max<int64_t>(0, (n[u] - 1) * L[u]); v[u] < std::min(g.dims[u], (n[u] + 1) * L[u]); ++v[u])
    {
      const Role r = roles.role[g.linear_index(v[0], v[1], v[2])];
      if (r == Role::Wall || (viscera && r == Role::Viscera)) return true;
    }
  return false;
}

/// Where the CT's cranial cut opens onto the chest (MeshOptions::opens_onto_thorax): each lattice node's
/// share, per part, of the cut slice's voxel faces whose tissue opens onto it (viscera, or wall the
/// predicate names), in voxel faces, each face split among its cube's four corners in the plane
/// bilinearly by where its centre lies. Indexed [part][node index on the plane: n_u + (cubes_u + 1) n_w].
std::array<std::vector<double>, 2> thorax_face_shares(const VoxelRoles& roles, const Lattice& lat, const CubeVoxels& L,
                                                      int axis, int64_t slice, const MeshOptions& opt) {
  const Geometry& g = roles.geometry;
  const int u = (axis + 1) % 3, w = (axis + 2) % 3;
  const int64_t row = lat.cubes[u] + 1;
  std::array<std::vector<double>, 2> share;
  for (auto& s : share) s.assign(std::size_t(row * (lat.cubes[w] + 1)), 0.0);
  std::array<int64_t, 3> v{};
  v[axis] = slice;
  for (v[w] = 0; v[w] < g.dims[w]; ++v[w])
    for (v[u] = 0; v[u] < g.dims[u]; ++v[u]) {
      const int64_t i = g.linear_index(v[0], v[1], v[2]);
      const Role r = roles.role[i];
      int p = -1;
      if (r == Role::Viscera && opt.model == MeshModel::WallViscera) p = int(Part::Viscera);
      else if (r == Role::Wall && opt.opens_onto_thorax(r, roles.label ? roles.label[i] : 0, roles.hu ? roles.hu[i] : 0.0f))
        p = int(Part::Wall);
      if (p < 0) continue;
      // The voxel's centre in lattice units along u and w (node n sits at voxel corner n·L).
      const double su = (double(v[u]) + 0.5) / double(L[u]), sw = (double(v[w]) + 0.5) / double(L[w]);
      const int64_t nu = int64_t(su), nw = int64_t(sw);
      const double fu = su - double(nu), fw = sw - double(nw);
      share[p][std::size_t(nu + row * nw)] += (1 - fu) * (1 - fw);
      share[p][std::size_t(nu + 1 + row * nw)] += fu * (1 - fw);
      share[p][std::size_t(nu + row * (nw + 1))] += (1 - fu) * fw;
      share[p][std::size_t(nu + 1 + row * (nw + 1))] += fu * fw;
    }
  return share;
}

/// The face of voxel (i,j,k) on its `side` (±1) along `axis`: its centre in index space, and in world
/// metres with its area vector (m²) out of the voxel.
struct VoxelFace {
  Vec3 centre_index, centre_m, area_m2;
};
VoxelFace voxel_face(const Geometry& g, int64_t i, int64_t j, int64_t k, int axis, int side) {
  VoxelFace f;
  f.centre_index = Vec3(double(i), double(j), double(k));
  f.centre_index[axis] += 0.5 * side;
  Vec3 du = Vec3::Zero(), dw = Vec3::Zero(), out = Vec3::Zero();
  du[(axis + 1) % 3] = 1.0;
  dw[(axis + 2) % 3] = 1.0;
  out[axis] = side;
  const Vec3 c = g.to_world(f.centre_index);
  f.centre_m = c * units::kMetresPerMm;
  f.area_m2 = (g.to_world(f.centre_index + du) - c).cross(g.to_world(f.centre_index + dw) - c) *
              (units::kMetresPerMm * units::kMetresPerMm);
  if (f.area_m2.dot(g.to_world(f.centre_index + out) - c) < 0) f.area_m2 = -f.area_m2;
  return f;
}

/// Barycentric weights of world point x_m (metres) in tetrahedron t at rest.
std::array<double, 4> rest_barycentric(const Mesh& m, int32_t t, const Vec3& x_m) {
  const auto& tv = m.tets[t];
  const Vec3& X0 = m.rest_m[tv[0]];
  Mat3 dm;
  dm << m.rest_m[tv[1]] - X0, m.rest_m[tv[2]] - X0, m.rest_m[tv[3]] - X0;
  const Vec3 w = dm.inverse() * (x_m - X0);
  return {1.0 - w.sum(), w[0], w[1], w[2]};
}

/// Cube (a,b,c)'s local coordinates u ∈ [0,1]³ of a point given in voxel index space.
std::array<double, 3> cube_local(const Vec3& index, int64_t a, int64_t b, int64_t c, const CubeVoxels& L) {
  return {(index[0] + 0.5 - double(a * L[0])) / L[0], (index[1] + 0.5 - double(b * L[1])) / L[1],
          (index[2] + 0.5 - double(c * L[2])) / L[2]};
}

/// The wall labels of MeshOptions::attached_labels, looked up per voxel.
struct AttachedLabels {
  LabelSet ids;
  explicit AttachedLabels(const std::vector<int>& list) : ids(list) {}
  /// Whether wall voxel v carries an attached label.
  bool holds(const VoxelRoles& roles, int64_t v) const { return roles.label && ids.contains(roles.label[v]); }
};

/// Marks the nodes of attached interfaces (Mesh::node_attached): for every face between a wall voxel
/// of an attached label and a viscera voxel, the corners of the wall voxel's cube in the wall's mesh
/// and of the viscera voxel's cube in the viscera's. Counts those faces, both sides, as the cavity's.
void mark_attached_nodes(Mesh& m, const VoxelRoles& roles, const CubeVoxels& L, const std::vector<int32_t> (&node_id)[kParts],
                         const Lattice& lat, const AttachedLabels& attached) {
  m.node_attached.assign(std::size_t(m.node_count()), 0);
  if (attached.ids.empty()) return;
  const Geometry& g = roles.geometry;
  auto mark_cube = [&](int p, int64_t i, int64_t j, int64_t k) {
    const int64_t a = i / L[0], b = j / L[1], c = k / L[2];
    for (int corner = 0; corner < 8; ++corner) {
      const auto o = lattice::corner_offset(corner);
      const int32_t id = node_id[p][lat.node_index(a + o[0], b + o[1], c + o[2])];
      if (id >= 0) m.node_attached[id] = 1;
    }
  };
  // The faces found slice by slice on every core (10⁸ voxels), their cubes marked after.
  struct Face { int64_t wall[3], viscera[3]; };
  std::vector<std::vector<Face>> per_slice(std::size_t(g.dims[2]));
#pragma omp parallel for schedule(dynamic, 4)
  for (int64_t k = 0; k < g.dims[2]; ++k)
    for (int64_t j = 0; j < g.dims[1]; ++j)
      for (int64_t i = 0; i < g.dims[0]; ++i) {
        const int64_t v = g.linear_index(i, j, k);
        if (roles.role[v] != Role::Wall || !attached.holds(roles, v)) continue;
        for (int axis = 0; axis < 3; ++axis)
          for (int side = -1; side <= 1; side += 2) {
            int64_t n[3] = {i, j, k};
            n[axis] += side;
            if (n[axis] < 0 || n[axis] >= g.dims[axis]) continue;
            if (roles.role[g.linear_index(n[0], n[1], n[2])] != Role::Viscera) continue;
            per_slice[std::size_t(k)].push_back({{i, j, k}, {n[0], n[1], n[2]}});
          }
      }
  for (const auto& faces : per_slice)
    for (const Face& f : faces) {
      mark_cube(0, f.wall[0], f.wall[1], f.wall[2]);
      mark_cube(1, f.viscera[0], f.viscera[1], f.viscera[2]);
      m.stats.attached_faces += 2;
    }
}

/// The pressure loads (mesh.h): every voxel face between a voxel of part p and one of the other
/// part's role, split into 4 triangles (centre and each edge) so each lies in one tetrahedron face
/// when L = 1, carried by part p's tetrahedron in the voxel's cube that holds the triangle's centroid.
/// The same faces make the contact surfaces between wall and viscera (mesh.h).
void build_pressure_loads(Mesh& m, const VoxelRoles& roles, const Lattice& lat, const CubeVoxels& L,
                          const std::vector<uint8_t>& meshed, const std::vector<int32_t> (&first_tet)[kParts],
                          const AttachedLabels& attached) {
  const Geometry& g = roles.geometry;
  struct Accum {
    int32_t tet;
    std::array<Vec3, 4> b;
    int64_t faces;
  };
  std::vector<std::vector<Accum>> per_slab(std::size_t(lat.cubes[2]));
  std::vector<ContactFaces> contact_per_slab(std::size_t(lat.cubes[2]));
#pragma omp parallel for schedule(dynamic)
  for (int64_t c = 0; c < lat.cubes[2]; ++c) {
    std::vector<Accum>& out = per_slab[c];
    ContactFaces& contact = contact_per_slab[c];
    for (int64_t b = 0; b < lat.cubes[1]; ++b)
      for (int64_t a = 0; a < lat.cubes[0]; ++a) {
        const int64_t q = lat.cube_index(a, b, c);
        if (meshed[q] == 0) continue;
        const bool odd = ((a + b + c) & 1) != 0;
        Accum acc[kParts][5];
        for (int p = 0; p < kParts; ++p)
          for (int k = 0; k < 5; ++k) acc[p][k] = Accum{-1, {Vec3::Zero(), Vec3::Zero(), Vec3::Zero(), Vec3::Zero()}, 0};
        for (int64_t k = c * L[2]; k < std::min<int64_t>((c + 1) * L[2], g.dims[2]); ++k)
          for (int64_t j = b * L[1]; j < std::min<int64_t>((b + 1) * L[1], g.dims[1]); ++j)
            for (int64_t i = a * L[0]; i < std::min<int64_t>((a + 1) * L[0], g.dims[0]); ++i) {
              const Role r = roles.role[g.linear_index(i, j, k)];
              if (r != Role::Wall && r != Role::Viscera) continue;
              const int p = r == Role::Wall ? 0 : 1;
              if (!(meshed[q] & (1 << p))) continue;
              const Role other = p == 0 ? Role::Viscera : Role::Wall;
              for (int axis = 0; axis < 3; ++axis)
                for (int side = -1; side <= 1; side += 2) {
                  int64_t n[3] = {i, j, k};
                  n[axis] += side;
                  if (n[axis] < 0 || n[axis] >= g.dims[axis]) continue;
                  // The viscera's whole surface is the contact's slave side (solve/contact.h); the
                  // wall's faces towards viscera are its master side and, with the viscera's towards
                  // the wall, the cavity's.
                  const int64_t nv = g.linear_index(n[0], n[1], n[2]);
                  const Role beyond = roles.role[nv];
                  // An attached organ's face towards the viscera stays closed: no gas, no pressure.
                  const bool cavity =
                      beyond == other && !attached.holds(roles, p == 0 ? g.linear_index(i, j, k) : nv);
                  if (!cavity && !(p == 1 && beyond != Role::Viscera)) continue;
                  const VoxelFace face = voxel_face(g, i, j, k, axis, side);
                  {
                    const int32_t tet =
                        first_tet[p][q] + lattice::tet_holding(cube_local(face.centre_index, a, b, c, L), odd);
                    const auto& tv = m.tets[tet];
                    Mat3 dm;
                    dm << m.rest_m[tv[1]] - m.rest_m[tv[0]], m.rest_m[tv[2]] - m.rest_m[tv[0]],
                        m.rest_m[tv[3]] - m.rest_m[tv[0]];
                    contact.tet.push_back(tet);
                    contact.w.push_back(rest_barycentric(m, tet, face.centre_m));
                    contact.c.push_back(dm.transpose() * face.area_m2 / dm.determinant());
                    contact.part.push_back(Part(p));
                  }
                  if (!cavity) continue;
                  // The 4 triangles (centre, corner t, corner t+1) in index space.
                  const Vec3& centre = face.centre_index;
                  const int u = (axis + 1) % 3, w = (axis + 2) % 3;
                  const double cu[4] = {-0.5, 0.5, 0.5, -0.5}, cw[4] = {-0.5, -0.5, 0.5, 0.5};
                  for (int t = 0; t < 4; ++t) {
                    Vec3 p1 = centre, p2 = centre;
                    p1[u] += cu[t];
                    p1[w] += cw[t];
                    p2[u] += cu[(t + 1) % 4];
                    p2[w] += cw[(t + 1) % 4];
                    const Vec3 centroid = (centre + p1 + p2) / 3.0;
                    const Vec3 x1 = g.to_world(p1) * units::kMetresPerMm, x2 = g.to_world(p2) * units::kMetresPerMm;
                    Vec3 area = 0.5 * (x1 - face.centre_m).cross(x2 - face.centre_m);
                    if (area.dot(face.area_m2) < 0) area = -area;
                    const int kt = lattice::tet_holding(cube_local(centroid, a, b, c, L), odd);
                    Accum& ac = acc[p][kt];
                    ac.tet = first_tet[p][q] + kt;
                    const auto w4 = rest_barycentric(m, ac.tet, g.to_world(centroid) * units::kMetresPerMm);
                    for (int v = 0; v < 4; ++v) ac.b[v] += w4[v] * area;
                  }
                  ++acc[p][0].faces;   // counted once per face, whichever tetrahedra carry it
                }
            }
        for (int p = 0; p < kParts; ++p) {
          int64_t faces = acc[p][0].faces;
          for (int k = 0; k < 5; ++k) {
            if (acc[p][k].tet < 0) continue;
            acc[p][k].faces = faces;
            faces = 0;
            out.push_back(acc[p][k]);
          }
        }
      }
  }
  for (const ContactFaces& slab : contact_per_slab) {
    ContactFaces& all = m.contact;
    all.tet.insert(all.tet.end(), slab.tet.begin(), slab.tet.end());
    all.w.insert(all.w.end(), slab.w.begin(), slab.w.end());
    all.c.insert(all.c.end(), slab.c.begin(), slab.c.end());
    all.part.insert(all.part.end(), slab.part.begin(), slab.part.end());
  }
  for (const auto& slab : per_slab)
    for (const Accum& ac : slab) {
      const auto& tv = m.tets[ac.tet];
      const Vec3& X0 = m.rest_m[tv[0]];
      Mat3 dm;
      dm << m.rest_m[tv[1]] - X0, m.rest_m[tv[2]] - X0, m.rest_m[tv[3]] - X0;
      const double det = dm.determinant();
      std::array<Vec3, 4> cvec;
      for (int v = 0; v < 4; ++v) cvec[v] = dm.transpose() * ac.b[v] / det;
      m.load_tet.push_back(ac.tet);
      m.load_c.push_back(cvec);
      m.stats.cavity_faces += ac.faces;
    }
  m.stats.pressure_tetrahedra = int64_t(m.load_tet.size());
}

/// The bone the viscera may be pushed against (mesh.h's ContactFaces): every face of a fixed voxel
/// towards a voxel that is neither fixed nor wall (viscera, or the space between), in a cube the
/// viscera mesh or next to one. The wall's side of bone is left out: the viscera reach it only through
/// the wall, whose own faces already stop them.
void build_bone_obstacles(Mesh& m, const VoxelRoles& roles, const Lattice& lat, const CubeVoxels& L,
                          const std::vector<uint8_t>& meshed) {
  const Geometry& g = roles.geometry;
  std::vector<uint8_t> near_viscera(meshed.size(), 0);   // the viscera's cubes dilated by one
  for (int64_t c = 0; c < lat.cubes[2]; ++c)
    for (int64_t b = 0; b < lat.cubes[1]; ++b)
      for (int64_t a = 0; a < lat.cubes[0]; ++a) {
        if (!(meshed[lat.cube_index(a, b, c)] & 2)) continue;
        for (int64_t z = c - 1; z <= c + 1; ++z)
          for (int64_t y = b - 1; y <= b + 1; ++y)
            for (int64_t x = a - 1; x <= a + 1; ++x)
              if (lat.inside(x, y, z)) near_viscera[lat.cube_index(x, y, z)] = 1;
      }
  auto viscera_cube = [&](int64_t i, int64_t j, int64_t k) {
    return near_viscera[lat.cube_index(i / L[0], j / L[1], k / L[2])] != 0;
  };
  // Slice by slice on every core (10⁸ voxels), joined in slice order: the faces in one pass's order.
  struct Faces { std::vector<Vec3> centre_m, area_m2; };
  std::vector<Faces> per_slice(std::size_t(g.dims[2]));
#pragma omp parallel for schedule(dynamic, 4)
  for (int64_t k = 0; k < g.dims[2]; ++k) {
    Faces& out = per_slice[std::size_t(k)];
    for (int64_t j = 0; j < g.dims[1]; ++j)
      for (int64_t i = 0; i < g.dims[0]; ++i) {
        if (roles.role[g.linear_index(i, j, k)] != Role::Fixed) continue;
        for (int axis = 0; axis < 3; ++axis)
          for (int side = -1; side <= 1; side += 2) {
            int64_t n[3] = {i, j, k};
            n[axis] += side;
            if (n[axis] < 0 || n[axis] >= g.dims[axis]) continue;
            const Role beyond = roles.role[g.linear_index(n[0], n[1], n[2])];
            if (beyond == Role::Fixed || beyond == Role::Wall) continue;
            if (!viscera_cube(i, j, k)) continue;
            const VoxelFace face = voxel_face(g, i, j, k, axis, side);   // out of the bone
            out.centre_m.push_back(face.centre_m);
            out.area_m2.push_back(face.area_m2);
          }
      }
  }
  for (const Faces& f : per_slice) {
    m.contact.fixed_centre_m.insert(m.contact.fixed_centre_m.end(), f.centre_m.begin(), f.centre_m.end());
    m.contact.fixed_area_m2.insert(m.contact.fixed_area_m2.end(), f.area_m2.begin(), f.area_m2.end());
  }
}

Lattice lattice_of(const Geometry& g, const CubeVoxels& L) {
  Lattice lat;
  lat.cubes = L.cubes_for(g.dims);
  return lat;
}

/// Which parts mesh each cube (bit p: part p): those with a voxel of their role in it, among the
/// cubes whose centre lies in the region of interest.
std::vector<uint8_t> meshed_parts(const VoxelRoles& roles, const Lattice& lat, const MeshOptions& opt) {
  const Geometry& g = roles.geometry;
  const CubeVoxels& L = opt.cube_voxels;
  const bool with_viscera = opt.model == MeshModel::WallViscera;
  std::vector<uint8_t> meshed(std::size_t(lat.cubes[0] * lat.cubes[1] * lat.cubes[2]), 0);
  // One layer of cubes per iteration: each thread writes only its own layers' cubes.
#pragma omp parallel for schedule(static)
  for (int64_t c = 0; c < lat.cubes[2]; ++c)
    for (int64_t k = c * L[2]; k < std::min<int64_t>((c + 1) * L[2], g.dims[2]); ++k)
      for (int64_t j = 0; j < g.dims[1]; ++j) {
        const Role* row = roles.role + g.linear_index(0, j, k);
        uint8_t* cube_row = meshed.data() + lat.cube_index(0, j / L[1], c);
        for (int64_t a = 0; a < lat.cubes[0]; ++a)
          for (int64_t i = a * L[0]; i < std::min<int64_t>((a + 1) * L[0], g.dims[0]); ++i) {
            const Role r = row[i];
            if (r == Role::Wall || (with_viscera && r == Role::Viscera)) cube_row[a] |= r == Role::Wall ? 1 : 2;
          }
      }
  if (opt.roi_min_mm && opt.roi_max_mm)
    for (int64_t c = 0; c < lat.cubes[2]; ++c)
      for (int64_t b = 0; b < lat.cubes[1]; ++b)
        for (int64_t a = 0; a < lat.cubes[0]; ++a) {
          const Vec3 centre =
              g.to_world(Vec3((a + 0.5) * L[0] - 0.5, (b + 0.5) * L[1] - 0.5, (c + 0.5) * L[2] - 0.5));
          if (!(centre.array() >= opt.roi_min_mm->array()).all() || !(centre.array() <= opt.roi_max_mm->array()).all())
            meshed[lat.cube_index(a, b, c)] = 0;
        }
  return meshed;
}

}  // namespace

MeshFootprint estimate_mesh_footprint(const VoxelRoles& roles, const MeshOptions& opt) {
  const Geometry& g = roles.geometry;
  const CubeVoxels& L = opt.cube_voxels;
  if (!L.valid()) throw InputError("mesh.cube_voxels must be at least 1 on every axis");
  const Lattice lat = lattice_of(g, L);
  const std::vector<uint8_t> meshed = meshed_parts(roles, lat, opt);
  MeshFootprint fp;
  fp.cubes = int64_t(meshed.size());
  std::vector<uint8_t> corner(std::size_t(lat.node_count()), 0);   // bit p: part p has a node here
  for (int64_t c = 0; c < lat.cubes[2]; ++c)
    for (int64_t b = 0; b < lat.cubes[1]; ++b)
      for (int64_t a = 0; a < lat.cubes[0]; ++a) {
        const uint8_t parts = meshed[lat.cube_index(a, b, c)];
        if (!parts) continue;
        fp.part_cubes += (parts & 1) + (parts >> 1);
        for (int k = 0; k < 8; ++k) {
          const auto o = lattice::corner_offset(k);
          corner[lat.node_index(a + o[0], b + o[1], c + o[2])] |= parts;
        }
      }
  for (uint8_t parts : corner) fp.nodes += (parts & 1) + (parts >> 1);
  // The faces the loads and contacts sit on (build_pressure_loads, build_bone_obstacles): viscera
  // towards anything else, wall towards viscera (the cavity's faces among them), bone towards
  // neither bone nor wall (counted whether or not viscera are near: an upper bound).
  const bool with_viscera = opt.model == MeshModel::WallViscera;
  int64_t fixed_faces = 0, contact_faces = 0, cavity_faces = 0;
#pragma omp parallel for schedule(static) reduction(+ : fixed_faces, contact_faces, cavity_faces)
  for (int64_t k = 0; k < g.dims[2]; ++k)
    for (int64_t j = 0; j < g.dims[1]; ++j)
      for (int64_t i = 0; i < g.dims[0]; ++i) {
        const Role r = roles.role[g.linear_index(i, j, k)];
        if (r == Role::Other || (r == Role::Fixed && !with_viscera)) continue;
        const int64_t at[3] = {i, j, k};
        for (int axis = 0; axis < 3; ++axis)
          for (int side = -1; side <= 1; side += 2) {
            int64_t n[3] = {at[0], at[1], at[2]};
            n[axis] += side;
            if (n[axis] < 0 || n[axis] >= g.dims[axis]) continue;
            const Role beyond = roles.role[g.linear_index(n[0], n[1], n[2])];
            if (r == Role::Fixed) fixed_faces += beyond != Role::Fixed && beyond != Role::Wall;
            else if (r == Role::Viscera) contact_faces += beyond != Role::Viscera;
            else contact_faces += beyond == Role::Viscera;
            cavity_faces += (r == Role::Wall && beyond == Role::Viscera) || (r == Role::Viscera && beyond == Role::Wall);
          }
      }
  fp.fixed_faces += fixed_faces;
  fp.contact_faces += contact_faces;
  fp.cavity_faces += cavity_faces;
  // Bytes. Arrays filled by push_back may hold up to twice their size (the growth factor 2); what is
  // gathered per slab and then appended exists in both while it is appended.
  const uint64_t tets = 5 * uint64_t(fp.part_cubes);
  const uint64_t springs = 3 * uint64_t(fp.nodes) + 6 * uint64_t(fp.part_cubes);   // axis edges + face diagonals
  const uint64_t loads = std::min<uint64_t>(uint64_t(fp.cavity_faces), tets);      // one per tetrahedron at most
  const uint64_t lattice_scratch = uint64_t(fp.cubes) * (sizeof(CubeContent) + 1 + 1 + 2 * sizeof(int32_t)) +
                                   uint64_t(lat.node_count()) * 2 * sizeof(int32_t);
  const uint64_t per_tet = 2 * (sizeof(std::array<int32_t, 4>) + sizeof(Part) + sizeof(uint16_t) + 5 * sizeof(double) +
                                sizeof(std::array<int32_t, 6>)) +
                           6 * sizeof(std::pair<int64_t, int64_t>);   // the edge sort, reserved exactly
  const uint64_t per_node =
      2 * (sizeof(Vec3) + sizeof(Part) + sizeof(uint8_t) + sizeof(std::array<int32_t, 3>) + sizeof(double)) +
      sizeof(uint8_t) +   // node_attached, sized once
      (opt.opens_onto_thorax ? 2 * (sizeof(int32_t) + sizeof(Vec3)) : 0);   // thorax_node, thorax_area_m2 (a bound)
  const uint64_t per_spring = 2 * (sizeof(std::array<int32_t, 2>) + 3 * sizeof(double));
  const uint64_t per_contact_face = 4 * (sizeof(int32_t) + sizeof(std::array<double, 4>) + sizeof(Vec3) + sizeof(Part));
  const uint64_t per_load = 2 * (sizeof(int32_t) + 2 * sizeof(std::array<Vec3, 4>) + sizeof(int64_t));
  fp.bytes = lattice_scratch + tets * (per_tet + opt.reserve_bytes_per_tet) +
             uint64_t(fp.nodes) * (per_node + opt.reserve_bytes_per_node) + springs * per_spring +
             uint64_t(fp.contact_faces) * per_contact_face + loads * per_load +
             uint64_t(fp.fixed_faces) * 4 * 2 * sizeof(Vec3);
  return fp;
}

void require_mesh_memory(const VoxelRoles& roles, const MeshOptions& opt) {
  const MemoryBudget budget = available_memory();
  const uint64_t need = estimate_mesh_footprint(roles, opt).bytes;
  if (need <= budget.bytes) return;
  // The smallest coarsening that fits (each estimate is two passes over the voxels, well under the
  // time the refused build would have taken): cubes of a growing edge in mm, each axis in whole
  // voxels of its own spacing (scene/scene_presets.h) and never finer than now, in steps of half the
  // finest spacing, so an isotropic lattice tries L + 1, L + 2, … as one L did.
  std::string advice = "narrow the region of interest (mesh.roi_min_mm, mesh.roi_max_mm)";
  const Vec3& spacing = roles.geometry.spacing_mm;
  const double edge_mm = opt.cube_voxels.edge_mm(spacing).maxCoeff(), step_mm = 0.5 * spacing.minCoeff();
  CubeVoxels last = opt.cube_voxels;
  for (int t = 1;; ++t) {
    CubeVoxels L = cube_voxels_for_mm(edge_mm + t * step_mm, spacing);
    for (int a = 0; a < 3; ++a) L[a] = std::max(L[a], opt.cube_voxels[a]);
    if (L.max() > 4 * opt.cube_voxels.max() + 4) break;
    if (L == last) continue;
    last = L;
    MeshOptions coarser = opt;
    coarser.cube_voxels = L;
    const uint64_t b = estimate_mesh_footprint(roles, coarser).bytes;
    if (b > budget.bytes) continue;
    char mm[32];
    std::snprintf(mm, sizeof mm, "%g", L.edge_mm(spacing).maxCoeff());
    const std::string voxels =
        L.uniform() ? L.text() : "[" + std::to_string(L[0]) + ", " + std::to_string(L[1]) + ", " + std::to_string(L[2]) + "]";
    advice = "raise mesh.cube_voxels to " + voxels + " (mesh.cube_mm " + mm + ", about " + format_bytes(b) + ") or " +
             advice;
    break;
  }
  require_memory(need, budget, "the mesh of " + opt.cube_voxels.text() + "-voxel cubes", advice);
}

uint64_t mesh_bytes(const Mesh& m) {
  auto held = [](const auto& v) { return uint64_t(v.capacity()) * sizeof(v[0]); };
  const ContactFaces& c = m.contact;
  return held(m.rest_m) + held(m.node_part) + held(m.hold) + held(m.node_lattice) + held(m.node_attached) + held(m.mass_kg) + held(m.tets) +
         held(m.tet_part) + held(m.tet_label) + held(m.tet_fraction) + held(m.tet_cube) + held(m.tet_rest_volume_m3) +
         held(m.tet_young_pa) + held(m.tet_poisson) + held(m.tet_fibre) + held(m.tet_fibre_k1_pa) + held(m.tet_springs) + held(m.springs) + held(m.spring_rest_m) +
         held(m.spring_k) + held(m.spring_c) + held(m.load_tet) + held(m.load_c) + held(c.tet) + held(c.w) + held(c.c) +
         held(c.part) + held(c.fixed_centre_m) + held(c.fixed_area_m2) + held(m.thorax_node) + held(m.thorax_area_m2);
}

Mesh build_mesh(const VoxelRoles& roles, const MeshOptions& opt, const std::function<double(Role, int)>& young_pa_for) {
  return build_mesh(roles, opt, VoxelYoungFn([&](Role r, int label, float) { return young_pa_for(r, label); }));
}

Mesh build_mesh(const VoxelRoles& roles, const MeshOptions& opt, const VoxelYoungFn& young_pa_for) {
  const Geometry& g = roles.geometry;
  const CubeVoxels& L = opt.cube_voxels;
  if (!L.valid()) throw InputError("mesh.cube_voxels must be at least 1 on every axis");
  const Lattice lat = lattice_of(g, L);
  require_mesh_memory(roles, opt);

  const SampleTets samples(L);
  const std::vector<CubeContent> content = classify_cubes(roles, lat, samples, young_pa_for, opt.poisson_for);
  const std::array<int64_t, 5> tet_samples[2] = {samples.per_tet(0), samples.per_tet(1)};
  const bool with_viscera = opt.model == MeshModel::WallViscera;

  const std::vector<uint8_t> meshed = meshed_parts(roles, lat, opt);

  Mesh m;
  m.grid = g;
  m.cube_voxels = L;
  m.cubes = lat.cubes;

  // Nodes: one per lattice corner per part that meshes a cube touching it.
  std::vector<int32_t> node_id[kParts];
  for (int p = 0; p < kParts; ++p) node_id[p].assign(lat.node_count(), -1);
  auto node_of = [&](int p, int64_t a, int64_t b, int64_t c) -> int32_t {
    int32_t& id = node_id[p][lat.node_index(a, b, c)];
    if (id < 0) {
      id = int32_t(m.rest_m.size());
      m.rest_m.push_back(node_world_m(g, a, b, c, L));
      m.node_part.push_back(Part(p));
      m.hold.push_back(0);
      m.node_lattice.push_back({int32_t(a), int32_t(b), int32_t(c)});
    }
    return id;
  };

  std::vector<int32_t> first_tet[kParts];
  for (int p = 0; p < kParts; ++p) first_tet[p].assign(content.size(), -1);
  for (int64_t c = 0; c < lat.cubes[2]; ++c)
    for (int64_t b = 0; b < lat.cubes[1]; ++b)
      for (int64_t a = 0; a < lat.cubes[0]; ++a) {
        const int64_t q = lat.cube_index(a, b, c);
        if (!meshed[q]) continue;
        const bool odd = ((a + b + c) & 1) != 0;
        if (meshed[q] == 3) ++m.stats.doubled_cubes;
        for (int p = 0; p < kParts; ++p) {
          if (!(meshed[q] & (1 << p))) continue;
          ++(p == 0 ? m.stats.wall_cubes : m.stats.viscera_cubes);
          int32_t corner_node[8];
          for (int k = 0; k < 8; ++k) {
            const auto o = lattice::corner_offset(k);
            corner_node[k] = node_of(p, a + o[0], b + o[1], c + o[2]);
          }
          const Role role = p == 0 ? Role::Wall : Role::Viscera;
          const uint16_t label = content[q].label[p];
          const double floor_young = kMinTissueFraction * young_pa_for(role, label, 0.0f);
          first_tet[p][q] = int32_t(m.tets.size());
          const auto tets = lattice::cube_tets(odd);
          for (int k = 0; k < 5; ++k) {
            const auto& t = tets[k];
            std::array<int32_t, 4> tet{corner_node[t[0]], corner_node[t[1]], corner_node[t[2]], corner_node[t[3]]};
            double vol = signed_tet_volume(m.rest_m[tet[0]], m.rest_m[tet[1]], m.rest_m[tet[2]], m.rest_m[tet[3]]);
            if (vol < 0) { std::swap(tet[2], tet[3]); vol = -vol; }
            const int64_t tissue = content[q].tissue[p][k];
            const double total = double(tet_samples[odd][k]);
            m.tets.push_back(tet);
            m.tet_part.push_back(Part(p));
            m.tet_label.push_back(label);
            m.tet_cube.push_back(q);
            m.tet_rest_volume_m3.push_back(vol);
            m.tet_fraction.push_back(std::max(double(tissue) / total, kMinTissueFraction));
            m.tet_young_pa.push_back(std::max(
                double(tissue) / total * hill_modulus(content[q].young_sum[p][k], content[q].compliance_sum[p][k], tissue),
                floor_young));
            if (opt.poisson_for)
              m.tet_poisson.push_back(tissue > 0 ? content[q].poisson_sum[p][k] / double(tissue)
                                                 : opt.poisson_for(role, label, 0.0f));
          }
        }
      }
  if (m.tets.empty()) {
    std::ostringstream os;
    os << "nothing to mesh: no cube of " << L.text() << " voxels holds a wall"
       << (with_viscera ? " or viscera" : "") << " voxel" << (opt.roi_min_mm ? " inside the region of interest" : "");
    throw InputError(os.str());
  }

  // Fixed nodes: a node is held where a fixed voxel touches it (one of the 8 voxels sharing its
  // corner), in whichever parts have a node there. Bone inside a cube holds only the nodes that lie
  // in it; the fixed region does not grow with the cube.
  for (int64_t c = 0; c <= lat.cubes[2]; ++c)
    for (int64_t b = 0; b <= lat.cubes[1]; ++b)
      for (int64_t a = 0; a <= lat.cubes[0]; ++a) {
        const int64_t ni = lat.node_index(a, b, c);
        if (node_id[0][ni] < 0 && node_id[1][ni] < 0) continue;
        if (!touches_fixed(roles, a, b, c, L)) continue;
        for (int p = 0; p < kParts; ++p)
          if (node_id[p][ni] >= 0) m.hold[node_id[p][ni]] = kHoldAll;
      }

  // Cut faces: on each face of the CT's box that cuts tissue, the lattice plane nearest to it, held on
  // the face's normal and free in it (MeshOptions::cut_faces).
  if (opt.cut_faces == CutFaces::Slide)
    for (int axis = 0; axis < 3; ++axis) {
      // Not the front and back: a field of view that cuts the anterior skin leaves the wall free to
      // rise there (a mirror would hold it), and the back lies on the table, fixed.
      const uint8_t bit = world_hold_of(g, axis);
      if (!bit || bit == kHoldY) continue;
      const int64_t first = std::clamp<int64_t>(roles.ct_first[axis], 0, g.dims[axis] - 1);
      const int64_t last = roles.ct_last[axis] < 0 ? g.dims[axis] - 1 : std::clamp<int64_t>(roles.ct_last[axis], first, g.dims[axis] - 1);
      // A face between voxels b − 1 and b lies on lattice plane b / L; the nearest plane, a tie going
      // outwards (below the low face, above the high one), so no CT tissue is left beyond it by more
      // than half a cube.
      const struct { int64_t slice, plane; } faces[2] = {{first, (2 * first + L[axis] - 1) / (2 * L[axis])},
                                                         {last, (2 * (last + 1) + L[axis]) / (2 * L[axis])}};
      for (int side = 0; side < 2; ++side) {
        const auto& face = faces[side];
        // The face towards the head (world +z, RAS) may open onto the chest (MeshOptions::opens_onto_thorax).
        const bool cranial = bit == kHoldZ && opt.opens_onto_thorax && (g.direction(2, axis) > 0) == (side == 1);
        const std::array<std::vector<double>, 2> shares =
            cranial ? thorax_face_shares(roles, lat, L, axis, face.slice, opt) : std::array<std::vector<double>, 2>{};
        // One voxel face normal to the axis, out of the mesh: the same everywhere on an affine grid.
        const Vec3 voxel_face_m2 = voxel_face(g, 0, 0, 0, axis, side == 1 ? 1 : -1).area_m2;
        std::array<int64_t, 3> n{};
        n[axis] = face.plane;
        const int u = (axis + 1) % 3, w = (axis + 2) % 3;
        for (n[w] = 0; n[w] <= lat.cubes[w]; ++n[w])
          for (n[u] = 0; n[u] <= lat.cubes[u]; ++n[u]) {
            const int64_t ni = lat.node_index(n[0], n[1], n[2]);
            if (node_id[0][ni] < 0 && node_id[1][ni] < 0) continue;
            if (!cut_through_tissue(roles, n, axis, face.slice, L, with_viscera)) continue;
            for (int p = 0; p < kParts; ++p) {
              const int32_t id = node_id[p][ni];
              if (id < 0) continue;
              const double share = cranial ? shares[p][std::size_t(n[u] + (lat.cubes[u] + 1) * n[w])] : 0.0;
              if (share > 0.0 && m.hold[id] != kHoldAll) {
                m.thorax_node.push_back(id);
                m.thorax_area_m2.push_back(share * voxel_face_m2);
              } else {
                m.hold[id] |= bit;
              }
            }
          }
      }
    }

  const AttachedLabels attached(opt.attached_labels);
  build_pressure_loads(m, roles, lat, L, meshed, first_tet, attached);
  mark_attached_nodes(m, roles, L, node_id, lat, attached);
  if (with_viscera) build_bone_obstacles(m, roles, lat, L, meshed);

  // Springs: unique tetrahedron edges (per part: parts never share nodes).
  std::vector<std::pair<int64_t, int64_t>> edges;   // (node-pair key, 6·tet + local edge)
  edges.reserve(m.tets.size() * 6);
  const int64_t N = m.node_count();
  for (int64_t t = 0; t < int64_t(m.tets.size()); ++t) {
    const auto& v = m.tets[t];
    for (int e = 0; e < 6; ++e) {
      const int32_t x = v[kTetEdges[e][0]], y = v[kTetEdges[e][1]];
      edges.emplace_back(int64_t(std::min(x, y)) * N + std::max(x, y), 6 * t + e);
    }
  }
  std::sort(edges.begin(), edges.end());
  m.tet_springs.assign(m.tets.size(), {});
  for (std::size_t e = 0; e < edges.size(); ++e) {
    if (e == 0 || edges[e].first != edges[e - 1].first) {
      const int32_t i = int32_t(edges[e].first / N), j = int32_t(edges[e].first % N);
      m.springs.push_back({i, j});
      m.spring_rest_m.push_back((m.rest_m[i] - m.rest_m[j]).norm());
    }
    m.tet_springs[edges[e].second / 6][edges[e].second % 6] = int32_t(m.springs.size() - 1);
  }

  m.stats.nodes = N;
  m.stats.tetrahedra = int64_t(m.tets.size());
  m.stats.springs = int64_t(m.springs.size());
  for (int64_t i = 0; i < N; ++i) {
    m.stats.fixed_nodes += m.hold[i] == kHoldAll;
    m.stats.cut_face_nodes += m.hold[i] != 0 && m.hold[i] != kHoldAll;
    ++(m.node_part[i] == Part::Wall ? m.stats.wall_nodes : m.stats.viscera_nodes);
  }
  m.stats.thorax_nodes = int64_t(m.thorax_node.size());
  return m;
}

}  // namespace pneumo
