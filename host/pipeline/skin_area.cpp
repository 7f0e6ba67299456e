#include "pipeline/skin_area.h"

#include <cmath>
#include <unordered_map>

namespace pneumo {

SkinArea wall_skin_area(const VoxelRoles& roles, const std::vector<uint8_t>& body, const CarryFn& carry,
                        double anterior_sector_deg) {
  SkinArea s;
  const Geometry& g = roles.geometry;
  // The body's axis per slice: the world centroid of its body voxels.
  std::vector<Vec3> axis(std::size_t(g.dims[2]), Vec3::Zero());
  for (int64_t k = 0; k < g.dims[2]; ++k) {
    Vec3 sum = Vec3::Zero();
    int64_t count = 0;
    for (int64_t j = 0; j < g.dims[1]; ++j)
      for (int64_t i = 0; i < g.dims[0]; ++i)
        if (body[std::size_t(g.linear_index(i, j, k))]) {
          sum += g.to_world(Vec3(double(i), double(j), double(k)));
          ++count;
        }
    if (count > 0) axis[std::size_t(k)] = sum / double(count);
  }
  // The grid axis nearest world posterior (−y) and its step, for the rays of over_viscera.
  int back_axis = 0;
  for (int a = 1; a < 3; ++a)
    if (std::abs(g.direction(1, a)) > std::abs(g.direction(1, back_axis))) back_axis = a;
  const int back_step = g.direction(1, back_axis) > 0.0 ? -1 : 1;
  // Whether the ray from wall voxel v towards the back meets viscera before bone or the grid's end:
  // the skin lies over the peritoneal cavity, not over the ribs, the pelvis or the thighs.
  auto over_viscera = [&](Index3 v) {
    for (v[back_axis] += back_step; v[back_axis] >= 0 && v[back_axis] < g.dims[back_axis]; v[back_axis] += back_step) {
      const Role r = roles.role[g.linear_index(v[0], v[1], v[2])];
      if (r == Role::Viscera) return true;
      if (r == Role::Fixed) return false;
    }
    return false;
  };
  const double cos_sector = std::cos(anterior_sector_deg * 3.14159265358979323846 / 180.0);
  // Within the sector: the face centre's offset from the axis, in the axial plane, leans from anterior
  // by at most the sector's angle.
  auto anterior = [&](const Vec3& centre, int64_t k) {
    const Vec3 d(centre[0] - axis[std::size_t(k)][0], centre[1] - axis[std::size_t(k)][1], 0.0);
    const double len = d.norm();
    return len > 0.0 && d[1] >= cos_sector * len;
  };
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
            const double rest = area(r[0], r[1], r[2], r[3]), deformed = area(d[0], d[1], d[2], d[3]);
            s.rest_mm2 += rest;
            s.deformed_mm2 += deformed;
            if (anterior(0.25 * (r[0] + r[1] + r[2] + r[3]), k) && over_viscera(v)) {
              s.anterior_rest_mm2 += rest;
              s.anterior_deformed_mm2 += deformed;
            }
            ++s.faces;
          }
      }
  return s;
}

}  // namespace pneumo
