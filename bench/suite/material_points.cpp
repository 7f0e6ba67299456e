#include "suite/material_points.h"

#include <algorithm>
#include <cmath>

#include "warp/point_map.h"
#include "warp/warp_mesh.h"

namespace pneumo::bench {

namespace {

std::vector<Vec3> strided(const std::vector<Vec3>& all, std::size_t max) {
  if (all.size() <= max || max == 0) return all;
  std::vector<Vec3> out;
  const double stride = double(all.size()) / double(max);
  for (std::size_t i = 0; i < max; ++i) out.push_back(all[std::size_t(double(i) * stride)]);
  return out;
}

}  // namespace

MaterialPoints material_points(const RoleVolume& roles, std::size_t max_per_set) {
  const Geometry& g = roles.geometry;
  const Index3 d = g.dims;
  std::vector<Vec3> skin, cavity;
  const auto role = [&](int64_t i, int64_t j, int64_t k) { return roles.role[std::size_t(g.linear_index(i, j, k))]; };
  for (int64_t k = 1; k + 1 < d[2]; ++k)
    for (int64_t j = 1; j + 1 < d[1]; ++j)
      for (int64_t i = 1; i + 1 < d[0]; ++i) {
        const Role r = role(i, j, k);
        if (r != Role::Wall && r != Role::Viscera) continue;
        const Role nb[6] = {role(i - 1, j, k), role(i + 1, j, k), role(i, j - 1, k),
                            role(i, j + 1, k), role(i, j, k - 1), role(i, j, k + 1)};
        const Role other_side = r == Role::Wall ? Role::Viscera : Role::Wall;
        const bool on_skin = r == Role::Wall && std::count(nb, nb + 6, Role::Other) > 0;
        const bool on_cavity = std::count(nb, nb + 6, other_side) > 0;
        const Vec3 p = g.to_world(Vec3(double(i), double(j), double(k)));
        if (on_skin) skin.push_back(p);
        if (on_cavity) cavity.push_back(p);
      }
  return MaterialPoints{strided(skin, max_per_set), strided(cavity, max_per_set)};
}

MappedPoints map_points(const MaterialPoints& p, const RoleVolume& roles, const Mesh& mesh,
                        const std::vector<Vec3>& x) {
  std::vector<Vec3> u(x.size());
  for (std::size_t n = 0; n < u.size(); ++n) u[n] = x[n] - mesh.rest_m[n];
  const WarpMesh wm = make_warp_mesh(mesh, u);
  const PointMap map(wm, roles.role.data());
  MappedPoints out;
  const auto carry = [&](const std::vector<Vec3>& in, std::vector<Vec3>& pts, std::vector<uint8_t>& ok) {
    pts.resize(in.size());
    ok.resize(in.size());
#pragma omp parallel for schedule(static)
    for (std::size_t i = 0; i < in.size(); ++i) {
      const MappedPoint m = map.to_deformed(in[i]);
      pts[i] = m.point_mm;
      ok[i] = m.carried ? 1 : 0;
    }
  };
  carry(p.skin_mm, out.skin_mm, out.skin_ok);
  carry(p.cavity_mm, out.cavity_mm, out.cavity_ok);
  return out;
}

PointError compare_points(const std::vector<Vec3>& a, const std::vector<uint8_t>& a_ok, const std::vector<Vec3>& b,
                          const std::vector<uint8_t>& b_ok) {
  PointError e;
  e.total = int64_t(a.size());
  double sum2 = 0;
  for (std::size_t i = 0; i < a.size() && i < b.size(); ++i) {
    if (!a_ok[i] || !b_ok[i]) continue;
    const double d = (a[i] - b[i]).norm();
    sum2 += d * d;
    e.max_mm = std::max(e.max_mm, d);
    ++e.compared;
  }
  e.rms_mm = e.compared ? std::sqrt(sum2 / double(e.compared)) : 0.0;
  return e;
}

}  // namespace pneumo::bench
