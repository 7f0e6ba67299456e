#pragma once
// Helpers the force tests share: random states near rest, the largest nodal force, and the
// central-difference check that a force is minus the gradient of its energy.
#include <algorithm>
#include <random>
#include <vector>

#include "mesh/mesh.h"

namespace pneumo {
inline namespace mesh_test_support {

inline double max_norm(const std::vector<Vec3>& f) {
  double s = 0.0;
  for (const auto& v : f) s = std::max(s, v.norm());
  return s;
}

/// max over nodes of |f_i + ∂E/∂x_i|, the gradient by central differences of step delta: zero when f
/// is the force of the potential E.
template <class Energy>
double max_gradient_mismatch(const std::vector<Vec3>& x, const std::vector<Vec3>& f, double delta, Energy&& energy) {
  double worst = 0.0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    Vec3 grad;
    for (int a = 0; a < 3; ++a) {
      std::vector<Vec3> xp = x, xm = x;
      xp[i][a] += delta;
      xm[i][a] -= delta;
      grad[a] = (energy(xp) - energy(xm)) / (2 * delta);
    }
    worst = std::max(worst, (f[i] + grad).norm());
  }
  return worst;
}

/// A random voxel grid (3 … max_dim voxels per axis, 1–4 mm spacing, anywhere within 100 mm of the
/// origin) of random roles and labels 0–3, voxel 0 wall so the mesh is never empty, and a random cube
/// size of 1 or 2 voxels: the meshes the device-equality tests draw.
struct RandomVoxels {
  Geometry grid;
  std::vector<Role> roles;
  std::vector<uint16_t> labels;
  MeshOptions options;
  VoxelRoles view() const { return VoxelRoles{grid, roles.data(), labels.data()}; }
};
inline RandomVoxels random_voxels(std::mt19937& rng, int max_dim) {
  std::uniform_int_distribution<int> dim(3, max_dim), role(0, 3), cube(1, 2);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  RandomVoxels v;
  v.grid.dims = {dim(rng), dim(rng), dim(rng)};
  v.grid.spacing_mm = Vec3(1.0 + 3 * u(rng), 1.0 + 3 * u(rng), 1.0 + 3 * u(rng));
  v.grid.origin_mm = Vec3(-100 + 200 * u(rng), -100 + 200 * u(rng), -100 + 200 * u(rng));
  v.roles.resize(v.grid.voxel_count());
  v.labels.resize(v.grid.voxel_count());
  for (auto& r : v.roles) r = Role(role(rng));
  v.roles[0] = Role::Wall;
  for (auto& l : v.labels) l = uint16_t(rng() % 4);
  v.options.cube_voxels = cube(rng);
  return v;
}

inline std::vector<Vec3> perturbed(const Mesh& m, std::mt19937& rng, double amplitude_m) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<Vec3> x = m.rest_m;
  for (auto& p : x) p += amplitude_m * Vec3(u(rng), u(rng), u(rng));
  return x;
}

}  // namespace mesh_test_support
}  // namespace pneumo
