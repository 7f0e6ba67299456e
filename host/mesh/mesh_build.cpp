// Builds the cube/tetrahedron mesh from voxel roles (method.md §3).
#include <algorithm>
#include <cmath>
#include <map>
#include <sstream>

#include "core/error.h"
#include "core/units.h"
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

/// Per cube: which roles its voxels hold, and each part's dominant label.
struct CubeContent {
  bool has[4] = {false, false, false, false};   // indexed by Role
  uint16_t label[kParts] = {0, 0};
};

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

std::vector<CubeContent> classify_cubes(const VoxelRoles& roles, const Lattice& lat, int L) {
  const Geometry& g = roles.geometry;
  std::vector<CubeContent> out(lat.cubes[0] * lat.cubes[1] * lat.cubes[2]);
#pragma omp parallel for schedule(dynamic) collapse(2)
  for (int64_t c = 0; c < lat.cubes[2]; ++c)
    for (int64_t b = 0; b < lat.cubes[1]; ++b)
      for (int64_t a = 0; a < lat.cubes[0]; ++a) {
        CubeContent cc;
        std::map<uint16_t, int> counts[kParts];
        for (int64_t k = c * L; k < std::min<int64_t>((c + 1) * L, g.dims[2]); ++k)
          for (int64_t j = b * L; j < std::min<int64_t>((b + 1) * L, g.dims[1]); ++j)
            for (int64_t i = a * L; i < std::min<int64_t>((a + 1) * L, g.dims[0]); ++i) {
              const int64_t v = g.linear_index(i, j, k);
              const Role r = roles.role[v];
              cc.has[static_cast<int>(r)] = true;
              if (roles.label && (r == Role::Wall || r == Role::Viscera))
                ++counts[r == Role::Wall ? 0 : 1][roles.label[v]];
            }
        for (int p = 0; p < kParts; ++p) {
          int best = -1;
          for (auto [id, n] : counts[p])
            if (n > best) { best = n; cc.label[p] = id; }
        }
        out[lat.cube_index(a, b, c)] = cc;
      }
  return out;
}

/// Rest position of lattice node (a,b,c): the corner of voxel (aL, bL, cL) at index aL − ½.
Vec3 node_world_m(const Geometry& g, int64_t a, int64_t b, int64_t c, int L) {
  const Vec3 idx(double(a * L) - 0.5, double(b * L) - 0.5, double(c * L) - 0.5);
  return g.to_world(idx) * units::kMetresPerMm;
}

}  // namespace

Mesh build_mesh(const VoxelRoles& roles, const MeshOptions& opt,
                const std::function<double(Role, int)>& young_pa_for) {
  const Geometry& g = roles.geometry;
  const int L = opt.cube_voxels;
  if (L < 1) throw InputError("mesh.cube_voxels must be at least 1");
  Lattice lat;
  for (int a = 0; a < 3; ++a) lat.cubes[a] = (g.dims[a] + L - 1) / L;

  const std::vector<CubeContent> content = classify_cubes(roles, lat, L);
  const bool with_viscera = opt.model == MeshModel::WallViscera;

  auto in_roi = [&](int64_t a, int64_t b, int64_t c) {
    if (!opt.roi_min_mm || !opt.roi_max_mm) return true;
    const Vec3 centre = g.to_world(Vec3((a + 0.5) * L - 0.5, (b + 0.5) * L - 0.5, (c + 0.5) * L - 0.5));
    return (centre.array() >= opt.roi_min_mm->array()).all() && (centre.array() <= opt.roi_max_mm->array()).all();
  };
  // Which parts mesh each cube.
  std::vector<uint8_t> meshed(content.size(), 0);   // bit p: part p meshes the cube
  for (int64_t c = 0; c < lat.cubes[2]; ++c)
    for (int64_t b = 0; b < lat.cubes[1]; ++b)
      for (int64_t a = 0; a < lat.cubes[0]; ++a) {
        const int64_t q = lat.cube_index(a, b, c);
        if (!in_roi(a, b, c)) continue;
        if (content[q].has[int(Role::Wall)]) meshed[q] |= 1;
        if (with_viscera && content[q].has[int(Role::Viscera)]) meshed[q] |= 2;
      }

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

  const auto faces = lattice::cube_faces();
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
          const double young = young_pa_for(role, label);
          for (const auto& t : lattice::cube_tets(odd)) {
            std::array<int32_t, 4> tet{corner_node[t[0]], corner_node[t[1]], corner_node[t[2]], corner_node[t[3]]};
            double vol = signed_tet_volume(m.rest_m[tet[0]], m.rest_m[tet[1]], m.rest_m[tet[2]], m.rest_m[tet[3]]);
            if (vol < 0) { std::swap(tet[2], tet[3]); vol = -vol; }
            m.tets.push_back(tet);
            m.tet_part.push_back(Part(p));
            m.tet_label.push_back(label);
            m.tet_cube.push_back(q);
            m.tet_rest_volume_m3.push_back(vol);
            m.tet_young_pa.push_back(young);
          }
          // Cavity triangles: faces on this part's boundary whose neighbour cube holds the other
          // part's role (the gas enters between wall and viscera there).
          const Vec3 cube_centre = node_world_m(g, a, b, c, L) * 0.5 + node_world_m(g, a + 1, b + 1, c + 1, L) * 0.5;
          for (const auto& f : faces) {
            int64_t n[3] = {a, b, c};
            n[f.axis] += f.side ? 1 : -1;
            if (!lat.inside(n[0], n[1], n[2])) continue;
            const int64_t nq = lat.cube_index(n[0], n[1], n[2]);
            if (meshed[nq] & (1 << p)) continue;   // interior face of this part
            const Role other = p == 0 ? Role::Viscera : Role::Wall;
            if (!content[nq].has[int(other)]) continue;
            for (auto tri : lattice::face_triangles(f, odd)) {
              std::array<int32_t, 3> t{corner_node[tri[0]], corner_node[tri[1]], corner_node[tri[2]]};
              const Vec3 &x0 = m.rest_m[t[0]], &x1 = m.rest_m[t[1]], &x2 = m.rest_m[t[2]];
              const Vec3 normal = (x1 - x0).cross(x2 - x0);
              if (normal.dot((x0 + x1 + x2) / 3.0 - cube_centre) < 0) std::swap(t[1], t[2]);
              m.cavity_tris.push_back(t);
              m.tri_part.push_back(Part(p));
            }
          }
        }
      }
  if (m.tets.empty()) {
    std::ostringstream os;
    os << "nothing to mesh: no cube of " << L << " voxels holds a wall"
       << (with_viscera ? " or viscera" : "") << " voxel" << (opt.roi_min_mm ? " inside the region of interest" : "");
    throw InputError(os.str());
  }

  // Fixed nodes: every corner of a cube that holds a fixed voxel, meshed or not (§3), so a wall that
  // touches the back across a cube face is anchored there.
  for (int64_t c = 0; c < lat.cubes[2]; ++c)
    for (int64_t b = 0; b < lat.cubes[1]; ++b)
      for (int64_t a = 0; a < lat.cubes[0]; ++a) {
        if (!content[lat.cube_index(a, b, c)].has[int(Role::Fixed)]) continue;
        for (int k = 0; k < 8; ++k) {
          const auto o = lattice::corner_offset(k);
          const int64_t ni = lat.node_index(a + o[0], b + o[1], c + o[2]);
          for (int p = 0; p < kParts; ++p)
            if (node_id[p][ni] >= 0) m.hold[node_id[p][ni]] = kHoldAll;
        }
      }

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
  m.stats.cavity_triangles = int64_t(m.cavity_tris.size());
  for (int64_t i = 0; i < N; ++i) {
    m.stats.fixed_nodes += m.hold[i] == kHoldAll;
    ++(m.node_part[i] == Part::Wall ? m.stats.wall_nodes : m.stats.viscera_nodes);
  }
  return m;
}

}  // namespace pneumo
