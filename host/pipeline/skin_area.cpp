#include "pipeline/skin_area.h"

#include <unordered_map>

namespace pneumo {

SkinArea wall_skin_area(const VoxelRoles& roles, const std::vector<uint8_t>& body, const CarryFn& carry) {
  SkinArea s;
  const Geometry& g = roles.geometry;
  const Role* role = roles.role;
  Index3 last;
  for (int a = 0; a < 3; ++a) last[a] = roles.ct_last[a] < 0 ? g.dims[a] - 1 : roles.ct_last[a];
  auto in_box = [&](const Index3& v) {
    for (int a = 0; a < 3; ++a)
      if (v[a] < roles.ct_first[a] || v[a] > last[a]) return false;
    return true;
  };
  // Corners are voxel corners, keyed by their doubled index (2i + 1 for the corner at i + ½), carried once.
  std::unordered_map<int64_t, Vec3> carried;
  const int64_t cx = 2 * g.dims[0] + 3, cy = 2 * g.dims[1] + 3;
  auto corner = [&](const Index3& twice) -> const Vec3& {
    const int64_t key = (twice[0] + 1) + cx * ((twice[1] + 1) + cy * (twice[2] + 1));
    auto it = carried.find(key);
    if (it != carried.end()) return it->second;
    const Vec3 rest = g.to_world(Vec3(0.5 * double(twice[0]), 0.5 * double(twice[1]), 0.5 * double(twice[2])));
    Vec3 moved = rest;
    if (!carry(rest, moved)) {
      moved = rest;
      ++s.corners_not_carried;
    }
    return carried.emplace(key, moved).first->second;
  };
  auto area = [](const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {   // quad a-b-c-d as two triangles
    return 0.5 * (b - a).cross(c - a).norm() + 0.5 * (c - a).cross(d - a).norm();
  };
  for (int64_t k = 0; k < g.dims[2]; ++k)
    for (int64_t j = 0; j < g.dims[1]; ++j)
      for (int64_t i = 0; i < g.dims[0]; ++i) {
        if (role[g.linear_index(i, j, k)] != Role::Wall) continue;
        const Index3 v{i, j, k};
        for (int axis = 0; axis < 3; ++axis)
          for (int side = -1; side <= 1; side += 2) {
            Index3 n = v;
            n[axis] += side;
            if (n[axis] < 0 || n[axis] >= g.dims[axis] || !in_box(n)) continue;
            const int64_t o = g.linear_index(n[0], n[1], n[2]);
            if (role[o] != Role::Other || body[std::size_t(o)]) continue;
            // The face's corners in doubled index coordinates, in cyclic order.
            const int u = (axis + 1) % 3, w = (axis + 2) % 3;
            Index3 c[4];
            const int du[4] = {-1, 1, 1, -1}, dw[4] = {-1, -1, 1, 1};
            for (int q = 0; q < 4; ++q) {
              c[q][axis] = 2 * v[axis] + side;
              c[q][u] = 2 * v[u] + du[q];
              c[q][w] = 2 * v[w] + dw[q];
            }
            Vec3 r[4], d[4];
            for (int q = 0; q < 4; ++q) {
              r[q] = g.to_world(Vec3(0.5 * double(c[q][0]), 0.5 * double(c[q][1]), 0.5 * double(c[q][2])));
              d[q] = corner(c[q]);
            }
            s.rest_mm2 += area(r[0], r[1], r[2], r[3]);
            s.deformed_mm2 += area(d[0], d[1], d[2], d[3]);
            ++s.faces;
          }
      }
  return s;
}

}  // namespace pneumo
