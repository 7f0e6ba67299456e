#include "warp/point_map.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "core/log.h"

#include "warp/warp_sampling.h"

namespace pneumo {

PointMap::PointMap(const WarpMesh& mesh, const Role* roles) : mesh_(mesh), roles_(roles) {
  usable_.resize(std::size_t(mesh.tet_count()));
  for (int64_t t = 0; t < mesh.tet_count(); ++t) usable_[std::size_t(t)] = !warp_tet_degenerate(mesh, t);
  rest_ = bin(false);
  deformed_ = bin(true);
}

PointMap::Bins PointMap::bin(bool deformed) const {
  Bins b;
  for (int a = 0; a < 3; ++a) b.cell[a] = std::max(1, mesh_.cube_voxels[a]);
  const int64_t T = mesh_.tet_count();
  auto vertex = [&](int64_t t, int c) {
    const int32_t n = mesh_.tets[std::size_t(t)][c];
    return deformed ? mesh_.deformed_ijk(n) : mesh_.rest_ijk[n];
  };
  Vec3 lo = Vec3::Constant(INFINITY), hi = Vec3::Constant(-INFINITY);
  for (int64_t t = 0; t < T; ++t)
    for (int c = 0; c < 4; ++c) lo = lo.cwiseMin(vertex(t, c)), hi = hi.cwiseMax(vertex(t, c));
  if (T == 0) return b;
  b.min = lo.array() - 1.0;
  for (int a = 0; a < 3; ++a) b.dims[a] = int64_t(std::floor((hi[a] + 1.0 - b.min[a]) / b.cell[a])) + 1;
  auto cell_range = [&](int64_t t, Index3& c0, Index3& c1) {
    Vec3 l = vertex(t, 0), h = l;
    for (int c = 1; c < 4; ++c) l = l.cwiseMin(vertex(t, c)), h = h.cwiseMax(vertex(t, c));
    const Vec3 margin = 4.0 * kWarpTolerance * (h - l);
    for (int a = 0; a < 3; ++a) {
      c0[a] = std::clamp<int64_t>(int64_t(std::floor((l[a] - margin[a] - b.min[a]) / b.cell[a])), 0, b.dims[a] - 1);
      c1[a] = std::clamp<int64_t>(int64_t(std::floor((h[a] + margin[a] - b.min[a]) / b.cell[a])), 0, b.dims[a] - 1);
    }
  };
  const int64_t cells = b.dims[0] * b.dims[1] * b.dims[2];
  b.start.assign(std::size_t(cells + 1), 0);
  for (int pass = 0; pass < 2; ++pass) {   // count, then fill (ascending ids per cell)
    std::vector<int64_t> fill(b.start.begin(), b.start.end() - 1);
    for (int64_t t = 0; t < T; ++t) {
      if (!usable_[std::size_t(t)]) continue;   // the warp skips them too, before and after
      Index3 c0, c1;
      cell_range(t, c0, c1);
      for (int64_t z = c0[2]; z <= c1[2]; ++z)
        for (int64_t y = c0[1]; y <= c1[1]; ++y)
          for (int64_t x = c0[0]; x <= c1[0]; ++x) {
            const int64_t c = x + b.dims[0] * (y + b.dims[1] * z);
            if (pass == 0) ++b.start[std::size_t(c + 1)];
            else b.ids[std::size_t(fill[std::size_t(c)]++)] = int32_t(t);
          }
    }
    if (pass == 0) {
      for (int64_t c = 0; c < cells; ++c) b.start[std::size_t(c + 1)] += b.start[std::size_t(c)];
      b.ids.resize(std::size_t(b.start.back()));
    }
  }
  return b;
}

const int32_t* PointMap::Bins::begin(const Vec3& p, const int32_t*& end) const {
  int64_t c[3];
  for (int a = 0; a < 3; ++a) {
    const double f = std::floor((p[a] - min[a]) / cell[a]);
    if (!(f >= 0.0 && f < double(dims[a]))) return end = nullptr;
    c[a] = int64_t(f);
  }
  const int64_t cell_id = c[0] + dims[0] * (c[1] + dims[1] * c[2]);
  end = ids.data() + start[std::size_t(cell_id + 1)];
  return ids.data() + start[std::size_t(cell_id)];
}

MappedPoint PointMap::map(const Vec3& mm, bool forward) const {
  const Geometry& g = mesh_.grid;
  const Vec3 p = g.to_index(mm);
  const SourceGrid grid{g.dims, nullptr, nullptr, roles_};
  MappedPoint out;
  out.point_mm = mm;
  const int32_t* end = nullptr;
  const int32_t* it = (forward ? rest_ : deformed_).begin(p, end);
  for (; it && it != end; ++it) {
    const auto& v = mesh_.tets[std::size_t(*it)];
    Vec3 x[4], d[4];
    for (int c = 0; c < 4; ++c) {
      d[c] = mesh_.disp_ijk[v[c]];
      x[c] = forward ? mesh_.rest_ijk[v[c]] : mesh_.deformed_ijk(v[c]);
    }
    Mat3 e, dd;
    e << x[1] - x[0], x[2] - x[0], x[3] - x[0];
    dd << d[1] - d[0], d[2] - d[0], d[3] - d[0];
    const Vec3 w = e.inverse() * (p - x[0]);
    if (1.0 - w.sum() < -kWarpTolerance || w.minCoeff() < -kWarpTolerance) continue;
    const Vec3 shift = d[0] + dd * w;
    const Vec3 other = forward ? Vec3(p + shift) : Vec3(p - shift);
    // The role that decides is the original frame's: the point itself, or the source it maps to.
    const Role role = grid.role_nearest(forward ? p : other);
    const bool accept = mesh_.tet_part[std::size_t(*it)] == Part::Wall ? role != Role::Viscera : role != Role::Wall;
    if (!accept) continue;
    out.point_mm = g.to_world(other);
    out.carried = true;
    out.tet = *it;
    return out;
  }
  return out;
}

MappedPoint PointMap::to_deformed(const Vec3& original_mm) const { return map(original_mm, true); }
MappedPoint PointMap::to_original(const Vec3& deformed_mm) const { return map(deformed_mm, false); }

PointMapFn deformed_point_fn(const PointMap& map, bool warn) {
  return [&map, warn](const Vec3& p) -> Vec3 {
    const MappedPoint m = map.to_deformed(p);
    if (!m.carried && warn) {
      char at[96];
      std::snprintf(at, sizeof at, "(%.1f, %.1f, %.1f) mm", p[0], p[1], p[2]);
      log::warn(std::string("the point ") + at + " lies in no tetrahedron that carries it (outside the wall and "
                "viscera meshes, or in tissue its tetrahedra refuse): it keeps its CT position while the tissue "
                "around it moves");
    }
    return m.point_mm;
  };
}

}  // namespace pneumo
