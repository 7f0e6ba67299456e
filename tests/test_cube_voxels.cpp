// Cubes sized per axis (core/cube_voxels.h): mesh.cube_mm gives each axis of the grid the
// whole number of voxels nearest to it, so cubes are near-cubic on anisotropic (clinical) grids.
//  - The rounding: every edge within half a voxel of cube_mm (at least one voxel), the presets' sizes on a
//    0.75 × 0.75 × 2.5 mm grid as the docs state them, and one L on every axis of an isotropic grid (the
//    meshes of before, unchanged).
//  - The scene: mesh.cube_voxels as one integer or [i, j, k], its messages, its echo.
//  - The mesh on an oblique anisotropic grid with cubes of 3 × 2 × 1 voxels: exact invariants (the lattice
//    edges are the cube's edges per axis to 1e-12; the tetrahedra's rest volumes sum to the meshed cubes'
//    volume, |det A|·L₀L₁L₂ each, to 1e-12 relative; a cube full of one tissue fills each of its
//    tetrahedra, fraction exactly 1, though its sample counts per axis differ).
//  - The pipeline's mesh of a scene at cube_mm 9 on a 1 × 1 × 3 mm grid: lattice spacing 9 mm on each axis.
//  - deformation.bin: version 2 written; a version 1 file still read for a mesh of one L, refused for another.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "io_test_support.h"
#include "core/cube_voxels.h"
#include "core/error.h"
#include "mesh/deformation_file.h"
#include "mesh/mesh.h"
#include "pipeline/scene_stages.h"
#include "scene/scene.h"
#include "scene/scene_presets.h"

using namespace pneumo;
using testing_support::ScratchDir;

namespace {

Geometry grid(const Index3& dims, const Vec3& spacing, const Mat3& direction = Mat3::Identity()) {
  Geometry g;
  g.dims = dims;
  g.spacing_mm = spacing;
  g.direction = direction;
  g.origin_mm = Vec3(-40.0, 12.5, 80.0);
  return g;
}

/// A block of wall voxels with a slab of viscera under it, and air around: two parts, partly filled cubes.
std::vector<Role> block_roles(const Geometry& g) {
  std::vector<Role> r(std::size_t(g.voxel_count()), Role::Other);
  for (int64_t k = 1; k + 1 < g.dims[2]; ++k)
    for (int64_t j = 1; j + 1 < g.dims[1]; ++j)
      for (int64_t i = 1; i + 1 < g.dims[0]; ++i)
        r[std::size_t(g.linear_index(i, j, k))] = j < g.dims[1] / 2 ? Role::Viscera : Role::Wall;
  return r;
}

}  // namespace

TEST(CubeVoxels, CubeMmGivesEveryAxisItsNearestWholeVoxels) {
  // On 0.75 × 0.75 × 2.5 mm voxels (a clinical abdomen): the presets' 12, 9 and 6 mm cubes.
  const Vec3 clinical(0.75, 0.75, 2.5);
  EXPECT_EQ(cube_voxels_for_mm(12.0, clinical), CubeVoxels(16, 16, 5));
  EXPECT_EQ(cube_voxels_for_mm(9.0, clinical), CubeVoxels(12, 12, 4));
  EXPECT_EQ(cube_voxels_for_mm(6.0, clinical), CubeVoxels(8, 8, 2));
  EXPECT_EQ(cube_voxels_for_mm(9.0, clinical).text(), "12×12×4");
  EXPECT_EQ(cube_voxels_for_mm(0.1, clinical), CubeVoxels(1));   // at least one voxel
  // Within half a voxel of cube_mm on every axis, for grids from isotropic to 1:6.
  for (const Vec3& s : {Vec3(0.7, 0.7, 2.5), Vec3(1.0, 1.0, 3.0), Vec3(0.5, 0.9, 3.0), Vec3(1.5, 1.5, 1.5)})
    for (double mm = 3.0; mm <= 16.0; mm += 0.5) {
      const CubeVoxels c = cube_voxels_for_mm(mm, s);
      for (int a = 0; a < 3; ++a) {
        if (c[a] > 1) {
          EXPECT_LE(std::abs(c.edge_mm(s)[a] - mm), 0.5 * s[a] + 1e-12) << mm << " mm, axis " << a;
        }
      }
    }
  // An isotropic grid: one L, the nearest whole number of voxels, as the single L always was.
  for (double mm : {4.5, 6.0, 9.0, 12.0})
    EXPECT_EQ(cube_voxels_for_mm(mm, Vec3::Constant(1.5)), CubeVoxels(int(std::lround(mm / 1.5))));
}

TEST(CubeVoxels, SceneTakesOneIntegerOrOnePerAxis) {
  const Scene one = parse_scene({{"mesh", {{"cube_voxels", 5}}}}, "scene.json");
  EXPECT_EQ(one.mesh.cube_voxels, CubeVoxels(5));
  EXPECT_EQ(one.echo()["mesh"]["cube_voxels"], 5);   // written back as given
  const Scene three = parse_scene({{"mesh", {{"cube_voxels", {12, 12, 4}}}}}, "scene.json");
  EXPECT_EQ(three.mesh.cube_voxels, CubeVoxels(12, 12, 4));
  EXPECT_EQ(three.echo()["mesh"]["cube_voxels"], nlohmann::json({12, 12, 4}));
  EXPECT_EQ(parse_scene(three.echo(), "scene.json").mesh.cube_voxels, CubeVoxels(12, 12, 4));
  auto message = [](const nlohmann::json& mesh) {
    try {
      parse_scene({{"mesh", mesh}}, "scene.json");
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  EXPECT_NE(message({{"cube_voxels", {12, 0, 4}}}).find("mesh.cube_voxels[1] = 0 is out of range"), std::string::npos)
      << message({{"cube_voxels", {12, 0, 4}}});
  EXPECT_NE(message({{"cube_voxels", {12, 12}}}).find("expected an integer or an array of 3 integers"), std::string::npos)
      << message({{"cube_voxels", {12, 12}}});
  EXPECT_NE(message({{"cube_voxels", {12, 12, 4.5}}}).find("has the wrong type"), std::string::npos);
  // cube_mm wins, per axis on the CT's grid; unset, cube_voxels as given.
  SceneMesh m;
  m.cube_voxels = CubeVoxels(2, 3, 4);
  const Geometry g = grid({10, 10, 10}, Vec3(0.75, 0.75, 2.5));
  EXPECT_EQ(cube_voxels_for(m, g), CubeVoxels(2, 3, 4));
  m.cube_mm = 9.0;
  EXPECT_EQ(cube_voxels_for(m, g), CubeVoxels(12, 12, 4));
}

TEST(CubeVoxels, MeshOfPerAxisCubesKeepsItsVolumeInvariants) {
  const Mat3 oblique = Eigen::AngleAxisd(0.4, Vec3(1, 2, 3).normalized()).toRotationMatrix();
  const Geometry g = grid({13, 12, 8}, Vec3(0.7, 0.9, 2.1), oblique);
  const std::vector<Role> roles = block_roles(g);
  MeshOptions o;
  o.cube_voxels = CubeVoxels(3, 2, 1);
  const Mesh m = build_mesh(VoxelRoles{g, roles.data(), nullptr}, o, [](Role, int) { return 10e3; });
  EXPECT_EQ(m.cube_voxels, CubeVoxels(3, 2, 1));
  EXPECT_EQ(m.cubes, (std::array<int64_t, 3>{5, 6, 8}));   // ceil(dims / L) per axis
  // Lattice edges: neighbours along axis a lie L_a voxels apart, A·L_a·e_a in mm.
  const Mat3 A = g.direction * g.spacing_mm.asDiagonal();
  std::map<std::array<int32_t, 4>, int64_t> at;   // (part, lattice a, b, c) → node
  for (int64_t n = 0; n < m.node_count(); ++n)
    at[{int32_t(m.node_part[n]), m.node_lattice[n][0], m.node_lattice[n][1], m.node_lattice[n][2]}] = n;
  int64_t edges = 0;
  for (const auto& [key, n] : at)
    for (int a = 0; a < 3; ++a) {
      std::array<int32_t, 4> next = key;
      ++next[std::size_t(a + 1)];
      const auto it = at.find(next);
      if (it == at.end()) continue;
      const Vec3 expected = 1e-3 * A.col(a) * o.cube_voxels[a];
      EXPECT_LT((m.rest_m[it->second] - m.rest_m[n] - expected).norm(), 1e-12);
      ++edges;
    }
  EXPECT_GT(edges, 300);
  // Tetrahedra: positive, and per part summing to that part's cubes times the cube's volume.
  const double cube_m3 = std::abs(A.determinant()) * o.cube_voxels.volume() * 1e-9;
  std::array<double, 2> volume{0, 0};
  std::array<std::set<int64_t>, 2> cubes;
  for (std::size_t t = 0; t < m.tets.size(); ++t) {
    const auto& v = m.tets[t];
    EXPECT_GT(signed_tet_volume(m.rest_m[v[0]], m.rest_m[v[1]], m.rest_m[v[2]], m.rest_m[v[3]]), 0.0);
    const int p = int(m.tet_part[t]);
    volume[std::size_t(p)] += m.tet_rest_volume_m3[t];
    cubes[std::size_t(p)].insert(m.tet_cube[t]);
  }
  for (int p = 0; p < 2; ++p) {
    EXPECT_EQ(int64_t(cubes[std::size_t(p)].size()) * 5,
              int64_t(std::count(m.tet_part.begin(), m.tet_part.end(), Part(p))));
    EXPECT_NEAR(volume[std::size_t(p)] / (double(cubes[std::size_t(p)].size()) * cube_m3), 1.0, 1e-12) << part_name(Part(p));
  }
  // A cube wholly inside the wall (voxels i 3–5, j 8–9, k 2 of cube (1, 4, 2)): every tetrahedron full.
  // Its sample counts per axis (6, 4, 4 per cube edge) hold different powers of 2, so some samples lie on
  // faces between tetrahedra; each goes to one of them alike in the cube and in the count of a full cube.
  const int64_t full = 1 + m.cubes[0] * (4 + m.cubes[1] * 2);
  int checked = 0;
  for (std::size_t t = 0; t < m.tets.size(); ++t)
    if (m.tet_cube[t] == full && m.tet_part[t] == Part::Wall) {
      EXPECT_EQ(m.tet_fraction[t], 1.0);
      ++checked;
    }
  EXPECT_EQ(checked, 5);
}

TEST(CubeVoxels, SceneMeshAtCubeMmIsNearCubicOnAnAnisotropicGrid) {
  // 1 × 1 × 3 mm voxels at the balanced preset's 9 mm: 9 × 9 × 3 voxels, 9 mm on every axis. By one L
  // from the coarsest axis (the rule before) the cubes were 3 × 3 × 9 mm, nine times as many.
  const Geometry g = grid({40, 40, 14}, Vec3(1.0, 1.0, 3.0));
  const std::vector<Role> roles = block_roles(g);
  Scene scene = parse_scene({{"mesh", {{"model", "wall_viscera"}}}}, "scene.json");
  scene.mesh.cube_mm = 9.0;
  const Mesh m = build_scene_mesh(VoxelRoles{g, roles.data(), nullptr}, scene);
  EXPECT_EQ(m.cube_voxels, CubeVoxels(9, 9, 3));
  const Vec3 edge = m.cube_voxels.edge_mm(g.spacing_mm);
  for (int a = 0; a < 3; ++a) EXPECT_NEAR(edge[a], 9.0, 0.5 * g.spacing_mm[a]);
  // Node spacing along each axis, measured on the mesh.
  Vec3 lo = Vec3::Constant(1e9), hi = -lo;
  Index3 lat_hi{0, 0, 0};
  for (int64_t n = 0; n < m.node_count(); ++n) {
    lo = lo.cwiseMin(m.rest_m[n]);
    hi = hi.cwiseMax(m.rest_m[n]);
    for (int a = 0; a < 3; ++a) lat_hi[a] = std::max<int64_t>(lat_hi[a], m.node_lattice[n][a]);
  }
  for (int a = 0; a < 3; ++a) EXPECT_NEAR(1e3 * (hi[a] - lo[a]) / double(lat_hi[a]), 9.0, 1e-9) << "axis " << a;
}

TEST(CubeVoxels, DeformationFileOfVersionOneIsReadForOneLAndRefusedOtherwise) {
  ScratchDir dir;
  const Geometry g = grid({9, 8, 6}, Vec3(1.0, 1.0, 2.0));
  const std::vector<Role> roles = block_roles(g);
  auto mesh_of = [&](const CubeVoxels& c) {
    MeshOptions o;
    o.cube_voxels = c;
    return build_mesh(VoxelRoles{g, roles.data(), nullptr}, o, [](Role, int) { return 10e3; });
  };
  const std::string path = dir.file("deformation.bin");
  auto as_version_one = [&](const Mesh& m) {   // the bytes an older pneumo wrote: version 1, its fingerprint
    std::fstream f(path, std::ios::in | std::ios::out | std::ios::binary);
    const uint32_t version = 1;
    const uint64_t fingerprint = mesh_fingerprint(m, 1);
    f.seekp(8);
    f.write(reinterpret_cast<const char*>(&version), sizeof version);
    f.seekp(32);
    f.write(reinterpret_cast<const char*>(&fingerprint), sizeof fingerprint);
  };
  for (const CubeVoxels& c : {CubeVoxels(2), CubeVoxels(2, 2, 1)}) {
    SCOPED_TRACE(c.text());
    const Mesh m = mesh_of(c);
    Deformation d;
    d.displacement_m.assign(std::size_t(m.node_count()), Vec3(1e-3, -2e-3, 0.5e-3));
    d.pressure_pa = 1600.0;
    write_deformation(path, m, d);
    {
      std::ifstream f(path, std::ios::binary);
      uint32_t version = 0;
      f.seekg(8);
      f.read(reinterpret_cast<char*>(&version), sizeof version);
      EXPECT_EQ(version, 2u);
    }
    EXPECT_EQ(read_deformation(path, m).displacement_m, d.displacement_m);
    as_version_one(m);
    if (c.uniform()) {
      EXPECT_EQ(read_deformation(path, m).displacement_m, d.displacement_m);
    } else {
      try {   // whatever its fingerprint says (0 here, version 1's for this mesh)
        read_deformation(path, m);
        ADD_FAILURE() << "a version 1 file read for a mesh of per-axis cubes";
      } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("written for another mesh"), std::string::npos) << e.what();
      }
    }
  }
  {   // What an older pneumo wrote for one L = 2, read against cubes of 2 × 2 × 1: another mesh.
    const Mesh old_mesh = mesh_of(CubeVoxels(2)), now = mesh_of(CubeVoxels(2, 2, 1));
    Deformation d;
    d.displacement_m.assign(std::size_t(old_mesh.node_count()), Vec3::Zero());
    write_deformation(path, old_mesh, d);
    as_version_one(old_mesh);
    EXPECT_THROW(read_deformation(path, now), InputError);
    EXPECT_EQ(read_deformation(path, old_mesh).displacement_m, d.displacement_m);
  }
  {   // A version this pneumo does not know: refused, naming the versions it reads.
    std::fstream f(path, std::ios::in | std::ios::out | std::ios::binary);
    const uint32_t version = 3;
    f.seekp(8);
    f.write(reinterpret_cast<const char*>(&version), sizeof version);
  }
  try {
    read_deformation(path, mesh_of(CubeVoxels(2)));
    ADD_FAILURE() << "version 3 read";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("this pneumo reads versions 1 and 2"), std::string::npos) << e.what();
  }
  // Fingerprints tell per-axis cubes apart: (2, 2, 1) is not (2, 2, 2), and version 2 is not version 1.
  EXPECT_NE(mesh_fingerprint(mesh_of(CubeVoxels(2, 2, 1))), mesh_fingerprint(mesh_of(CubeVoxels(2))));
  EXPECT_NE(mesh_fingerprint(mesh_of(CubeVoxels(2)), 1), mesh_fingerprint(mesh_of(CubeVoxels(2)), 2));
}
