// The cube/tetrahedron mesh (method.md §3) and its material (§4), against counts, volumes and stiffnesses
// derived by hand from the lattice, never from the code under test.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "core/error.h"
#include "core/units.h"
#include "load_test_support.h"
#include "mesh/cube_lattice.h"
#include "mesh/mesh.h"

namespace pneumo {
namespace {

constexpr double kYoungPa = 60e3;

struct Voxels {
  Geometry g;
  std::vector<Role> roles;
  Voxels(int64_t nx, int64_t ny, int64_t nz, double spacing_mm, Role fill = Role::Other) {
    g.dims = {nx, ny, nz};
    g.spacing_mm = Vec3::Constant(spacing_mm);
    roles.assign(g.voxel_count(), fill);
  }
  Role& at(int64_t i, int64_t j, int64_t k) { return roles[g.linear_index(i, j, k)]; }
};

/// One cube of 4×4×4 wall voxels meshed alone (L = 4: one sample per voxel, at its centre), of HU
/// `lower` in its lower half (k < 2) and `upper` above: what the tissue-mixing tests draw.
struct HalfCube {
  Voxels v{4, 4, 4, 1.0, Role::Wall};
  std::vector<float> hu;
  MeshOptions o;
  HalfCube(float lower, float upper) : hu(v.roles.size()) {
    for (int64_t k = 0; k < 4; ++k)
      for (int64_t j = 0; j < 4; ++j)
        for (int64_t i = 0; i < 4; ++i) hu[v.g.linear_index(i, j, k)] = k < 2 ? lower : upper;
    o.cube_voxels = 4;
    o.model = MeshModel::Wall;
  }
  VoxelRoles roles() const { return VoxelRoles{v.g, v.roles.data(), nullptr, hu.data()}; }
  /// Calls f(tetrahedron, lower half?) for each voxel centre, with the tetrahedron that holds it.
  template <class F>
  static void each_sample(F f) {
    for (int k = 0; k < 4; ++k)
      for (int j = 0; j < 4; ++j)
        for (int i = 0; i < 4; ++i) f(lattice::tet_holding({(i + 0.5) / 4, (j + 0.5) / 4, (k + 0.5) / 4}, false), k < 2);
  }
};

Mesh build(const Voxels& v, int L, MeshModel model = MeshModel::Wall, std::optional<Vec3> roi_min = std::nullopt,
           std::optional<Vec3> roi_max = std::nullopt) {
  MeshOptions o;
  o.cube_voxels = L;
  o.model = model;
  o.roi_min_mm = roi_min;
  o.roi_max_mm = roi_max;
  return build_mesh(VoxelRoles{v.g, v.roles.data(), nullptr}, o, [](Role, int) { return kYoungPa; });
}

using Key = std::array<int32_t, 3>;
std::pair<Key, Key> sorted_pair(const Key& a, const Key& b) { return a < b ? std::make_pair(a, b) : std::make_pair(b, a); }


/// Lloyd's per-tetrahedron spring constant (§4), written out here independently of material.cpp.
double lloyd_k(double E, double V) { return 2.0 * std::sqrt(2.0) / 25.0 * E * std::cbrt(6.0 * std::sqrt(2.0) * V); }

// ---- one cube ---------------------------------------------------------------------------------------------------

TEST(MeshSingleCube, CountsOrientationAndVolumes) {
  // Compared: one cube of wall voxels (L = 1 and L = 2) against the 5-tetrahedron split of §3: 8 nodes,
  // 5 tetrahedra, 18 springs (12 edges + 6 face diagonals), every tetrahedron positive at rest, volumes
  // summing to h³, the central (regular) tetrahedron h³/3 and the 4 corner ones h³/6.
  // Tolerance: 1e-14 relative; the volumes are triple products of coordinates that are exact multiples of
  // the spacing, so only a few roundings separate them from the closed form.
  for (int L : {1, 2}) {
    SCOPED_TRACE("L = " + std::to_string(L));
    const double spacing_mm = 3.0;
    Voxels v(L, L, L, spacing_mm, Role::Wall);
    const Mesh m = build(v, L);
    const double h = units::mm_to_m(L * spacing_mm);
    EXPECT_EQ(m.node_count(), 8);
    EXPECT_EQ(m.tets.size(), 5u);
    EXPECT_EQ(m.springs.size(), 18u);
    EXPECT_EQ(m.stats.wall_cubes, 1);
    int edges = 0, diagonals = 0;
    for (std::size_t s = 0; s < m.springs.size(); ++s) {
      const double len = (m.rest_m[m.springs[s][0]] - m.rest_m[m.springs[s][1]]).norm() / h;
      if (std::abs(len - 1.0) < 1e-12) ++edges;
      else if (std::abs(len - std::sqrt(2.0)) < 1e-12) ++diagonals;
      else ADD_FAILURE() << "spring " << s << " has length " << len << " h (neither an edge nor a face diagonal)";
      EXPECT_NEAR(m.spring_rest_m[s] / h, len, 1e-14);
    }
    EXPECT_EQ(edges, 12);
    EXPECT_EQ(diagonals, 6);
    double total = 0.0;
    int central = 0, corner = 0;
    for (std::size_t t = 0; t < m.tets.size(); ++t) {
      const auto& q = m.tets[t];
      const double vol = signed_tet_volume(m.rest_m[q[0]], m.rest_m[q[1]], m.rest_m[q[2]], m.rest_m[q[3]]);
      EXPECT_GT(vol, 0.0) << "tetrahedron " << t << " is not positively oriented";
      EXPECT_NEAR(m.tet_rest_volume_m3[t], vol, 1e-14 * h * h * h);
      total += vol;
      if (std::abs(vol - h * h * h / 3.0) < 1e-14 * h * h * h) ++central;
      else if (std::abs(vol - h * h * h / 6.0) < 1e-14 * h * h * h) ++corner;
      else ADD_FAILURE() << "tetrahedron " << t << " has volume " << vol / (h * h * h) << " h³";
    }
    EXPECT_EQ(central, 1);
    EXPECT_EQ(corner, 4);
    EXPECT_NEAR(total, h * h * h, 1e-14 * h * h * h);
  }
}

// ---- a block of cubes -------------------------------------------------------------------------------------------

TEST(MeshBlock, ClosedFormCountsAndOneDiagonalPerFace) {
  // Compared: an n×n×n block (n = 3, L = 1 and L = 2) against the lattice's closed forms: nodes (n+1)³,
  // tetrahedra 5n³, springs = cube edges 3n(n+1)² + face diagonals 3n²(n+1) (one per lattice face). No
  // spring appears twice, no spring is a body diagonal, and every lattice face holds exactly one of its two
  // diagonals (neighbouring cubes' patterns agree: no crossing diagonals). Exact integer comparisons.
  for (int L : {1, 2}) {
    SCOPED_TRACE("L = " + std::to_string(L));
    const int n = 3;
    Voxels v(n * L, n * L, n * L, 2.0, Role::Wall);
    const Mesh m = build(v, L);
    EXPECT_EQ(m.node_count(), (n + 1) * (n + 1) * (n + 1));
    EXPECT_EQ(int64_t(m.tets.size()), 5 * n * n * n);
    const int64_t cube_edges = 3 * n * (n + 1) * (n + 1), face_diagonals = 3 * n * n * (n + 1);
    EXPECT_EQ(int64_t(m.springs.size()), cube_edges + face_diagonals);
    EXPECT_EQ(m.stats.springs, cube_edges + face_diagonals);

    std::set<std::pair<Key, Key>> pairs;
    int64_t edges = 0, diagonals = 0;
    for (const auto& s : m.springs) {
      const Key a = m.node_lattice[s[0]], b = m.node_lattice[s[1]];
      EXPECT_TRUE(pairs.insert(sorted_pair(a, b)).second) << "duplicate spring";
      int differing = 0;
      for (int ax = 0; ax < 3; ++ax) {
        EXPECT_LE(std::abs(a[ax] - b[ax]), 1);
        differing += a[ax] != b[ax];
      }
      edges += differing == 1;
      diagonals += differing == 2;
      EXPECT_NE(differing, 3) << "a body diagonal is not an edge of the 5-tetrahedron split";
    }
    EXPECT_EQ(edges, cube_edges);
    EXPECT_EQ(diagonals, face_diagonals);

    // Every lattice face: corners in cyclic order, exactly one of (c0,c2), (c1,c3) is a spring.
    int64_t faces = 0;
    for (int ax = 0; ax < 3; ++ax) {
      const int u = (ax + 1) % 3, w = (ax + 2) % 3;
      for (int32_t p = 0; p <= n; ++p)
        for (int32_t i = 0; i < n; ++i)
          for (int32_t j = 0; j < n; ++j) {
            Key c[4];
            const int du[4] = {0, 1, 1, 0}, dw[4] = {0, 0, 1, 1};
            for (int q = 0; q < 4; ++q) {
              c[q][ax] = p;
              c[q][u] = i + du[q];
              c[q][w] = j + dw[q];
            }
            const int found = int(pairs.count(sorted_pair(c[0], c[2]))) + int(pairs.count(sorted_pair(c[1], c[3])));
            EXPECT_EQ(found, 1) << "face axis " << ax << " at " << p << " (" << i << "," << j << ")";
            ++faces;
          }
    }
    EXPECT_EQ(faces, face_diagonals);
  }
}

TEST(MeshMaterial, MassesSumToDensityTimesVolume) {
  // Compared: node masses m_i = ρ Σ V_t/4 (§4) against ρ·(block volume) in total, and at interior nodes
  // against a count done here. Face diagonals (the central tetrahedra's edges) join the lattice nodes whose
  // i+j+k is odd, so an odd interior node lies in the central tetrahedron and 3 corner ones of each of its 8
  // cubes: 8·(h³/3 + 3h³/6)/4 = 5/3 h³; an even one in a single corner tetrahedron of each: 8·(h³/6)/4 =
  // 1/3 h³. Their mean is ρh³, the value §4 quotes for "interior nodes" (true on average only: with the
  // 5-tetrahedron split the lumped masses alternate 5:1). Tolerance: 1e-13 relative (sums of a few hundred
  // exactly representable fractions of h³).
  const int n = 4;
  const double spacing_mm = 5.0, rho = 1096.0;
  Voxels v(n, n, n, spacing_mm, Role::Wall);
  Mesh m = build(v, 1);
  MaterialOptions mo;
  mo.density_kg_m3 = rho;
  assign_material(m, mo);
  const double h = units::mm_to_m(spacing_mm), cell = rho * h * h * h;
  double total = 0.0, interior_sum = 0.0;
  int interior = 0;
  for (int64_t i = 0; i < m.node_count(); ++i) {
    total += m.mass_kg[i];
    const auto& l = m.node_lattice[i];
    if (l[0] > 0 && l[0] < n && l[1] > 0 && l[1] < n && l[2] > 0 && l[2] < n) {
      const bool odd = (l[0] + l[1] + l[2]) % 2 != 0;
      EXPECT_NEAR(m.mass_kg[i], (odd ? 5.0 / 3.0 : 1.0 / 3.0) * cell, 1e-13 * cell);
      interior_sum += m.mass_kg[i];
      ++interior;
    }
  }
  EXPECT_EQ(interior, (n - 1) * (n - 1) * (n - 1));
  // (n−1)³ = 27 interior nodes: 14 odd and 13 even, so the mean is near (not at) ρh³.
  EXPECT_NEAR(interior_sum, (14 * 5.0 / 3.0 + 13 * 1.0 / 3.0) * cell, 1e-13 * interior_sum);
  EXPECT_NEAR(total, rho * std::pow(n * h, 3), 1e-13 * rho * std::pow(n * h, 3));
}

TEST(MeshMaterial, LloydStiffnessFromTheFormula) {
  // Compared: every spring's k (§4: Σ over the tetrahedra sharing the edge of (2√2/25)·E·(6√2·V_t)^(1/3))
  // against a count done here: within one cube a cube edge lies in exactly one corner tetrahedron (V = h³/6)
  // and a face diagonal in the central tetrahedron (V = h³/3) and two corner ones; so k = (cubes sharing the
  // edge) × k_corner for edges, and (cubes sharing it) × (k_central + 2 k_corner) for face diagonals.
  // Interior springs therefore have 4 k_corner = 0.508·E·h and 2(k_central + 2k_corner) = 0.828·E·h, the
  // values method.md §4 quotes. Tolerance: 1e-12 relative (a cube root and a sum of ≤ 12 terms); the quoted
  // 3-digit values are checked to ±5e-4 (their rounding).
  const int n = 3;
  const double spacing_mm = 4.0, scale = 0.925;
  Voxels v(n, n, n, spacing_mm, Role::Wall);
  Mesh m = build(v, 1);
  MaterialOptions mo;
  mo.spring_scale = scale;
  assign_material(m, mo);
  const double h = units::mm_to_m(spacing_mm);
  const double k_corner = scale * lloyd_k(kYoungPa, h * h * h / 6.0);
  const double k_central = scale * lloyd_k(kYoungPa, h * h * h / 3.0);
  EXPECT_NEAR(4 * k_corner / (scale * kYoungPa * h), 0.508, 5e-4);
  EXPECT_NEAR(2 * (k_central + 2 * k_corner) / (scale * kYoungPa * h), 0.828, 5e-4);
  int interior_edges = 0, interior_diagonals = 0;
  for (std::size_t s = 0; s < m.springs.size(); ++s) {
    const Key a = m.node_lattice[m.springs[s][0]], b = m.node_lattice[m.springs[s][1]];
    // Cubes containing both endpoints: per axis, lo ∈ [max(a,b) − 1, min(a,b)] inside [0, n).
    int cubes = 1, differing = 0;
    for (int ax = 0; ax < 3; ++ax) {
      const int lo = std::max({a[ax], b[ax]}) - 1, hi = std::min(a[ax], b[ax]);
      cubes *= std::max(0, std::min(hi, n - 1) - std::max(lo, 0) + 1);
      differing += a[ax] != b[ax];
    }
    const double expected = differing == 1 ? cubes * k_corner : cubes * (k_central + 2 * k_corner);
    EXPECT_NEAR(m.spring_k[s], expected, 1e-12 * expected) << "spring " << s << " (" << cubes << " cubes)";
    if (differing == 1 && cubes == 4) ++interior_edges;
    if (differing == 2 && cubes == 2) ++interior_diagonals;
  }
  // Interior edges: along an axis, (n) positions × (n−1)² interior lines × 3 axes; interior faces likewise.
  EXPECT_EQ(interior_edges, 3 * n * (n - 1) * (n - 1));
  EXPECT_EQ(interior_diagonals, 3 * (n - 1) * n * n);
}

TEST(MeshMaterial, DampingIsTwoZetaSqrtMassStiffness) {
  // Compared: every damper c against 2ζ√(m k) with m the mean of the two node masses (§4), recomputed here.
  // Tolerance: 1e-14 relative (one square root).
  Voxels v(3, 2, 2, 5.0, Role::Wall);
  Mesh m = build(v, 1);
  MaterialOptions mo;
  mo.damping_ratio = 0.3;
  assign_material(m, mo);
  for (std::size_t s = 0; s < m.springs.size(); ++s) {
    const double mass = 0.5 * (m.mass_kg[m.springs[s][0]] + m.mass_kg[m.springs[s][1]]);
    const double expected = 2.0 * 0.3 * std::sqrt(mass * m.spring_k[s]);
    EXPECT_NEAR(m.spring_c[s], expected, 1e-14 * expected);
  }
}

// ---- frames -----------------------------------------------------------------------------------------------------

TEST(MeshGeometry, FlippedAndRotatedAxesKeepPositiveTetrahedra) {
  // Compared: a 3×3×3 block on grids whose direction matrix flips an axis (diag(−1,1,1), a left-handed
  // index frame) or rotates and scales anisotropically, against the identity grid: the same node,
  // tetrahedron, spring and cavity counts, every tetrahedron positive in world space, total volume equal to
  // the block's, and the same spring rest lengths as a multiset (the world metric is what matters).
  // Tolerance: 1e-12 relative on volumes and lengths (rounding of the affine map).
  auto make = [](const Mat3& dir, const Vec3& spacing) {
    Voxels v(5, 5, 5, 1.0, Role::Viscera);
    v.g.spacing_mm = spacing;
    v.g.direction = dir;
    v.g.origin_mm = Vec3(10, -20, 30);
    for (int k = 1; k < 4; ++k)
      for (int j = 1; j < 4; ++j)
        for (int i = 1; i < 4; ++i) v.at(i, j, k) = Role::Wall;
    return v;
  };
  const Vec3 spacing(2.0, 3.0, 4.0);
  const Mesh ref = build(make(Mat3::Identity(), spacing), 1);
  Mat3 flip = Mat3::Identity();
  flip(0, 0) = -1.0;
  const Mat3 rot = Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized()).toRotationMatrix();
  const Mat3 rot_flip = rot * flip;
  for (const Mat3& dir : {flip, rot, rot_flip}) {
    SCOPED_TRACE("direction det " + std::to_string(dir.determinant()));
    const Mesh m = build(make(dir, spacing), 1);
    EXPECT_EQ(m.node_count(), ref.node_count());
    EXPECT_EQ(m.tets.size(), ref.tets.size());
    EXPECT_EQ(m.springs.size(), ref.springs.size());
    EXPECT_EQ(m.load_tet.size(), ref.load_tet.size());
    EXPECT_EQ(m.stats.cavity_faces, ref.stats.cavity_faces);
    const double block = 27 * spacing.prod() * 1e-9;
    double total = 0.0;
    for (const auto& q : m.tets) {
      const double vol = signed_tet_volume(m.rest_m[q[0]], m.rest_m[q[1]], m.rest_m[q[2]], m.rest_m[q[3]]);
      EXPECT_GT(vol, 0.0);
      total += vol;
    }
    EXPECT_NEAR(total, block, 1e-12 * block);
    std::vector<double> a(ref.spring_rest_m), b(m.spring_rest_m);
    std::sort(a.begin(), a.end());
    std::sort(b.begin(), b.end());
    for (std::size_t s = 0; s < a.size(); ++s) EXPECT_NEAR(a[s], b[s], 1e-12 * a[s]);
    // The pressure loads (wall surrounded by viscera: the whole surface) still point out of the block,
    // and their area vectors close: a closed surface's sum to zero.
    const Vec3 centre = m.grid.to_world(Vec3(2, 2, 2)) * units::kMetresPerMm;
    Vec3 closure = Vec3::Zero();
    double area = 0.0;
    for (std::size_t l = 0; l < m.load_tet.size(); ++l) {
      const Vec3 a = load_area_vector(m, l);
      EXPECT_GT(a.dot(load_centroid(m, l) - centre), 0.0);
      closure += a;
      area += a.norm();
    }
    EXPECT_LE(closure.norm(), 1e-12 * area);
  }
}

// ---- two parts --------------------------------------------------------------------------------------------------

/// 2×2 cubes across (L = 4), three layers: viscera z 0–6, a 2-voxel wall slab z 7–8, air above. The middle
/// layer holds both (doubled); the bottom only viscera; the top only wall.
Voxels slab_on_viscera() {
  Voxels v(8, 8, 12, 2.0, Role::Other);
  for (int k = 0; k < 12; ++k)
    for (int j = 0; j < 8; ++j)
      for (int i = 0; i < 8; ++i) v.at(i, j, k) = k <= 6 ? Role::Viscera : k <= 8 ? Role::Wall : Role::Other;
  return v;
}

/// Which cubes (linear index) each part meshes, from the tetrahedra.
std::set<int64_t> cubes_of(const Mesh& m, Part p) {
  std::set<int64_t> s;
  for (std::size_t t = 0; t < m.tets.size(); ++t)
    if (m.tet_part[t] == p) s.insert(m.tet_cube[t]);
  return s;
}


TEST(MeshParts, DoubledCubesSeparateNodesAndLoadTheVoxelInterface) {
  // Compared: a 2-voxel wall slab on viscera, L = 4 spanning both (the middle cube layer holds both roles),
  // against §3: 4 doubled cubes meshed once in each part (wall 8 cubes, viscera 8), two node sets that share
  // no node (no spring or tetrahedron joins the parts; counts are (2+1)²×3 lattice nodes per part), and
  // pressure loads on both parts at the voxel interface inside the doubled layer (below). Exact counts;
  // orientation by sign; areas and the centre of pressure to rounding.
  const Voxels v = slab_on_viscera();
  const Mesh m = build(v, 4, MeshModel::WallViscera);
  EXPECT_EQ(m.stats.doubled_cubes, 4);
  EXPECT_EQ(m.stats.wall_cubes, 8);
  EXPECT_EQ(m.stats.viscera_cubes, 8);
  EXPECT_EQ(m.stats.wall_nodes, 27);
  EXPECT_EQ(m.stats.viscera_nodes, 27);
  EXPECT_EQ(m.node_count(), 54);
  for (std::size_t t = 0; t < m.tets.size(); ++t)
    for (int32_t n : m.tets[t]) EXPECT_EQ(m.node_part[n], m.tet_part[t]);
  for (const auto& s : m.springs) EXPECT_EQ(m.node_part[s[0]], m.node_part[s[1]]);
  // Nodes of the doubled layer exist twice, at the same place, once per part.
  std::map<std::pair<Key, Part>, int> seen;
  for (int64_t i = 0; i < m.node_count(); ++i) EXPECT_EQ(++seen[std::make_pair(m.node_lattice[i], m.node_part[i])], 1);

  Vec3 centroid[2] = {Vec3::Zero(), Vec3::Zero()};
  int count[2] = {0, 0};
  for (int64_t i = 0; i < m.node_count(); ++i) {
    centroid[int(m.node_part[i])] += m.rest_m[i];
    ++count[int(m.node_part[i])];
  }
  for (int p = 0; p < 2; ++p) centroid[p] /= count[p];
  const std::set<int64_t> cubes[2] = {cubes_of(m, Part::Wall), cubes_of(m, Part::Viscera)};
  // Loads: the interface is the voxel plane between k = 6 and 7 (z = 13 mm), inside the doubled cubes (which
  // span z = 7…15 mm), not on a cube face. Each part's loads sit in its copies of the doubled cubes, point
  // at the other part, sum to the interface's area (4 cube faces of 8 mm) and their centre of pressure is
  // the voxel plane itself, within rounding.
  Vec3 area[2] = {Vec3::Zero(), Vec3::Zero()};
  double moment_z[2] = {0, 0};
  const double h = units::mm_to_m(8.0);
  for (std::size_t l = 0; l < m.load_tet.size(); ++l) {
    const int p = int(m.tet_part[m.load_tet[l]]);
    EXPECT_TRUE(cubes[0].count(m.tet_cube[m.load_tet[l]]) && cubes[1].count(m.tet_cube[m.load_tet[l]]));
    const Vec3 a = load_area_vector(m, l);
    area[p] += a;
    moment_z[p] += a.norm() * load_centroid(m, l)[2];
    EXPECT_GT(a.dot(centroid[1 - p] - centroid[p]), 0.0) << "load " << l << " faces away from the other part";
  }
  for (int p = 0; p < 2; ++p) {
    EXPECT_NEAR(area[p].norm(), 4 * h * h, 1e-12 * h * h);
    EXPECT_NEAR(moment_z[p] / area[p].norm(), units::mm_to_m(13.0), 1e-12);
  }
  EXPECT_NEAR((area[0] + area[1]).norm(), 0.0, 1e-12 * h * h);
  EXPECT_EQ(m.stats.cavity_faces, 2 * 8 * 8);   // 8×8 voxel faces, seen from both sides
}

TEST(MeshParts, WallOnlyModelKeepsTheWallsPressureLoads) {
  // Compared: the same voxels with mesh.model = wall: no viscera cube, node or tetrahedron, the wall mesh
  // identical in size to the two-part model's wall (8 cubes, 27 nodes), and its 8 pressure loads still
  // there (the neighbour voxels are viscera even though they are not meshed), pointing out of the wall
  // (down, −z, towards the viscera). Exact counts.
  const Voxels v = slab_on_viscera();
  const Mesh m = build(v, 4, MeshModel::Wall);
  EXPECT_EQ(m.stats.viscera_cubes, 0);
  EXPECT_EQ(m.stats.doubled_cubes, 0);
  EXPECT_EQ(m.stats.wall_cubes, 8);
  EXPECT_EQ(m.node_count(), 27);
  for (Part p : m.node_part) EXPECT_EQ(p, Part::Wall);
  for (Part p : m.tet_part) EXPECT_EQ(p, Part::Wall);
  ASSERT_GE(m.load_tet.size(), 8u);   // at least the 2 under each cube face, more where the plane cuts a cube
  ASSERT_LE(m.load_tet.size(), 20u);  // at most the 5 of each of the 4 cubes
  Vec3 total = Vec3::Zero();
  for (std::size_t l = 0; l < m.load_tet.size(); ++l) {
    const Vec3 a = load_area_vector(m, l);
    EXPECT_LT(a[2], 0.0) << "load " << l << " points up, into the wall";
    total += a;
  }
  const double h = units::mm_to_m(8.0);
  EXPECT_NEAR(total[2], -4 * h * h, 1e-12 * h * h);
}

// ---- fixed voxels, region of interest, empty input ---------------------------------------------------------------

/// The lattice nodes a fixed voxel touches: node a (at voxel index aL − ½) is a corner of voxel i when
/// aL = i or aL = i + 1.
std::set<Key> fixed_corners(const Voxels& v, int L) {
  std::set<Key> s;
  for (int64_t k = 0; k < v.g.dims[2]; ++k)
    for (int64_t j = 0; j < v.g.dims[1]; ++j)
      for (int64_t i = 0; i < v.g.dims[0]; ++i)
        if (v.roles[v.g.linear_index(i, j, k)] == Role::Fixed)
          for (int c = 0; c < 8; ++c) {
            const int64_t corner[3] = {i + (c & 1), j + ((c >> 1) & 1), k + ((c >> 2) & 1)};
            if (corner[0] % L || corner[1] % L || corner[2] % L) continue;
            s.insert({int32_t(corner[0] / L), int32_t(corner[1] / L), int32_t(corner[2] / L)});
          }
  return s;
}

TEST(MeshFixed, FixedVoxelsHoldTheNodesTheyTouchAndNothingElse) {
  // Compared: which nodes are held, against the lattice nodes a fixed voxel touches (mesh.h: held only where
  // bone is, not wherever a cube holds some), in three cases: (a) L = 1, a fixed voxel inside a wall block:
  // its cube is not meshed, yet its 8 corners are nodes of the neighbouring wall cubes and are all held;
  // (b) L = 2, one fixed voxel in a wall cube: only the cube's corner that the voxel touches is held, not the
  // other 7 (the old cube-wide rule held all 8); (c) the same with a viscera voxel in the cube too: both
  // parts' copies of that corner are held (2 nodes). Every other node is free (hold 0). Exact.
  struct Case {
    const char* name;
    int L;
    MeshModel model;
    int64_t expected_fixed;
  };
  for (const Case& cs : {Case{"unmeshed fixed cube", 1, MeshModel::Wall, 8},
                         Case{"meshed wall cube with a fixed voxel", 2, MeshModel::Wall, 1},
                         Case{"doubled cube with a fixed voxel", 2, MeshModel::WallViscera, 2}}) {
    SCOPED_TRACE(cs.name);
    Voxels v(6, 6, 6, 1.0, Role::Wall);
    if (cs.L == 1) {
      v.at(2, 3, 1) = Role::Fixed;
    } else {
      v.at(2, 2, 2) = Role::Fixed;
      if (cs.model == MeshModel::WallViscera) v.at(3, 3, 3) = Role::Viscera;
    }
    const Mesh m = build(v, cs.L, cs.model);
    const std::set<Key> corners = fixed_corners(v, cs.L);
    int64_t held = 0;
    for (int64_t i = 0; i < m.node_count(); ++i) {
      const bool should = corners.count(m.node_lattice[i]) > 0;
      EXPECT_EQ(m.hold[i], should ? kHoldAll : 0) << "node at lattice (" << m.node_lattice[i][0] << ","
                                                  << m.node_lattice[i][1] << "," << m.node_lattice[i][2] << ")";
      held += m.hold[i] == kHoldAll;
    }
    EXPECT_EQ(held, cs.expected_fixed);
    EXPECT_EQ(m.stats.fixed_nodes, cs.expected_fixed);
  }
}

TEST(MeshRoi, CubesOutsideTheRegionAreNotMeshed) {
  // Compared: a 4×2×2 wall block (L = 1, 10 mm voxels, origin 0) with a region of interest holding the cube
  // centres x ≤ 15 mm, against a 2×2×2 block: 27 nodes, 40 tetrahedra, every tetrahedron's cube centre
  // inside the region. Exact counts.
  Voxels v(4, 2, 2, 10.0, Role::Wall);
  const Mesh m = build(v, 1, MeshModel::Wall, Vec3(-100, -100, -100), Vec3(15, 100, 100));
  EXPECT_EQ(m.node_count(), 27);
  EXPECT_EQ(m.tets.size(), 40u);
  for (const auto& l : m.node_lattice) EXPECT_LE(l[0], 2);
}

TEST(MeshErrors, NothingToMeshThrowsInputError) {
  // Compared: inputs that leave nothing to mesh (all air; viscera only in a wall-only model; a region of
  // interest outside the body) against §3's contract: InputError, never an empty mesh.
  Voxels air(3, 3, 3, 1.0, Role::Other);
  EXPECT_THROW(build(air, 1), InputError);
  Voxels viscera(3, 3, 3, 1.0, Role::Viscera);
  EXPECT_THROW(build(viscera, 1, MeshModel::Wall), InputError);
  EXPECT_NO_THROW(build(viscera, 1, MeshModel::WallViscera));
  Voxels wall(3, 3, 3, 1.0, Role::Wall);
  EXPECT_THROW(build(wall, 1, MeshModel::Wall, Vec3(50, 50, 50), Vec3(60, 60, 60)), InputError);
  Voxels fixed_only(3, 3, 3, 1.0, Role::Fixed);
  EXPECT_THROW(build(fixed_only, 1, MeshModel::WallViscera), InputError);
}

TEST(MeshTissue, ModulusIsHillsMeanOfTheVoxelsInEachTetrahedron) {
  // Compared: one cube of 4×4×4 wall voxels (L = 4, one sample per voxel at its centre) whose lower half is
  // fat (HU −100 → 2 kPa) and upper half muscle (HU +50 → 60 kPa). Each tetrahedron's modulus against Hill's
  // mean of the voxels whose centres it holds, derived here from the points alone: ½ (arithmetic + harmonic
  // mean), to rounding; every mixed tetrahedron strictly between the Reuss and Voigt bounds; the volume
  // average below the Voigt average ½ (2 + 60) kPa = 31 kPa, which the Voigt mean alone gave (a mixed linear
  // tetrahedron cannot strain more in the fat than in the muscle). All fat gives 2 kPa in every tetrahedron
  // exactly, and the modulus by label alone (no CT) 60 kPa.
  HalfCube c(-100.0f, 50.0f);
  const VoxelYoungFn young = [](Role, int, float h) { return h <= -30.0f ? 2e3 : 60e3; };
  const Mesh half = build_mesh(c.roles(), c.o, young);
  ASSERT_EQ(half.tets.size(), 5u);
  double sum[5] = {0, 0, 0, 0, 0}, compliance[5] = {0, 0, 0, 0, 0};
  int n[5] = {0, 0, 0, 0, 0};
  HalfCube::each_sample([&](int t, bool lower) {
    const double e = lower ? 2e3 : 60e3;
    sum[t] += e;
    compliance[t] += 1.0 / e;
    ++n[t];
  });
  double ev = 0.0, vol = 0.0;
  int mixed = 0;
  for (int t = 0; t < 5; ++t) {
    const double voigt = sum[t] / n[t], reuss = n[t] / compliance[t];
    EXPECT_NEAR(half.tet_young_pa[t], 0.5 * (voigt + reuss), 1e-9 * voigt) << "tetrahedron " << t;
    if (voigt - reuss > 1.0) {
      ++mixed;
      EXPECT_GT(half.tet_young_pa[t], reuss);
      EXPECT_LT(half.tet_young_pa[t], voigt);
    }
    ev += half.tet_young_pa[t] * half.tet_rest_volume_m3[t];
    vol += half.tet_rest_volume_m3[t];
  }
  EXPECT_GE(mixed, 4);   // the corner tetrahedra reach across the mid-plane, and so does the central one
  EXPECT_LT(ev / vol, 0.9 * 31e3);
  const HalfCube fat(-100.0f, -100.0f);
  for (double e : build_mesh(fat.roles(), fat.o, young).tet_young_pa) EXPECT_DOUBLE_EQ(e, 2e3);
  const Mesh no_ct = build_mesh(VoxelRoles{c.v.g, c.v.roles.data(), nullptr}, c.o, young);
  for (double e : no_ct.tet_young_pa) EXPECT_DOUBLE_EQ(e, 60e3);
}

TEST(MeshTissue, PoissonsRatioIsTheMeanOfTheVoxelsInEachTetrahedron) {
  // Compared: the same cube, lower half lung (HU −800 → ν 0.40), upper half muscle (ν 0.45), with
  // MeshOptions::poisson_for: each tetrahedron's ν is the mean over the voxel centres it holds, derived
  // here from the points alone; all lung gives 0.40 exactly. Without poisson_for the mesh leaves
  // tet_poisson to its caller (empty).
  HalfCube c(-800.0f, 50.0f);
  const VoxelYoungFn young = [](Role, int, float h) { return h <= -400.0f ? 1e3 : 60e3; };
  EXPECT_TRUE(build_mesh(c.roles(), c.o, young).tet_poisson.empty());
  c.o.poisson_for = [](Role, int, float h) { return h <= -400.0f ? 0.40 : 0.45; };
  const Mesh half = build_mesh(c.roles(), c.o, young);
  ASSERT_EQ(half.tet_poisson.size(), 5u);
  double sum[5] = {0, 0, 0, 0, 0};
  int n[5] = {0, 0, 0, 0, 0};
  HalfCube::each_sample([&](int t, bool lower) {
    sum[t] += lower ? 0.40 : 0.45;
    ++n[t];
  });
  for (int t = 0; t < 5; ++t) EXPECT_NEAR(half.tet_poisson[t], sum[t] / n[t], 1e-12) << "tetrahedron " << t;
  HalfCube lung(-800.0f, -800.0f);
  lung.o.poisson_for = c.o.poisson_for;
  for (double nu : build_mesh(lung.roles(), lung.o, young).tet_poisson) EXPECT_DOUBLE_EQ(nu, 0.40);
}

}  // namespace
}  // namespace pneumo
