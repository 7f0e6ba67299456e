// Lamé's hollow sphere under internal pressure (method.md §10), on an octant with symmetry planes.
#include <chrono>
#include <algorithm>
#include <cmath>
#include <map>
#include <set>

#include "core/units.h"
#include "validate/validate.h"

namespace pneumo {

double lame_sphere_u(double r, double a, double b, double p, double bulk, double shear) {
  return p * a * a * a / (b * b * b - a * a * a) * (r / (3.0 * bulk) + b * b * b / (4.0 * shear * r * r));
}

LameResult validate_lame_sphere(const LameOptions& o) {
  const auto t0 = std::chrono::steady_clock::now();
  // The sphere is voxelised at voxel_mm (each voxel by its centre) and meshed with cubes of
  // cube_mm, exactly as the pipeline meshes a CT: a cube holding any shell voxel is a wall cube.
  const double v = o.voxel_mm > 0.0 ? o.voxel_mm : o.cube_mm;
  const int L = int(std::lround(o.cube_mm / v));
  if (L < 1 || std::abs(L * v - o.cube_mm) > 1e-9 * o.cube_mm)
    throw std::invalid_argument("validate_lame_sphere: cube_mm must be a whole multiple of voxel_mm");
  const int64_t nv = (int64_t(std::ceil(o.outer_mm / o.cube_mm)) + 1) * L;
  Geometry g;
  g.dims = {nv, nv, nv};
  g.spacing_mm = Vec3::Constant(v);
  g.origin_mm = Vec3::Constant(0.5 * v);   // lattice nodes at multiples of the cube size; centre at 0
  std::vector<Role> roles(g.voxel_count());
#pragma omp parallel for schedule(static)
  for (int64_t k = 0; k < nv; ++k)
    for (int64_t j = 0; j < nv; ++j)
      for (int64_t i = 0; i < nv; ++i) {
        const double r = g.to_world(Vec3(i, j, k)).norm();
        // Inside the cavity: "viscera" so that the wall's inner faces are cavity triangles.
        roles[g.linear_index(i, j, k)] = r < o.inner_mm ? Role::Viscera : r <= o.outer_mm ? Role::Wall : Role::Other;
      }
  MeshOptions mo;
  mo.cube_voxels = L;
  mo.model = MeshModel::Wall;
  const double E = units::kpa_to_pa(o.young_kpa);
  Mesh m = build_mesh(VoxelRoles{g, roles.data(), nullptr}, mo, [&](Role, int) { return E; });
  assign_material(m, MaterialOptions{});
  for (int64_t i = 0; i < m.node_count(); ++i)
    for (int a = 0; a < 3; ++a)
      if (m.node_lattice[i][a] == 0) m.hold[i] |= uint8_t(1 << a);   // symmetry planes

  // Boundary nodes from the mesh itself: tetrahedron faces used once are on the boundary; those on
  // a symmetry plane are not surfaces of the sphere; cavity triangles are the inner surface.
  std::map<std::array<int32_t, 3>, int> face_uses;
  for (const auto& t : m.tets)
    for (int f = 0; f < 4; ++f) {
      std::array<int32_t, 3> key{t[(f + 1) % 4], t[(f + 2) % 4], t[(f + 3) % 4]};
      std::sort(key.begin(), key.end());
      ++face_uses[key];
    }
  std::set<std::array<int32_t, 3>> cavity;
  for (auto t : m.cavity_tris) {
    std::sort(t.begin(), t.end());
    cavity.insert(t);
  }
  std::vector<uint8_t> side(m.node_count(), 0);   // 1 inner, 2 outer
  for (const auto& [key, uses] : face_uses) {
    if (uses != 1) continue;
    bool on_plane = false;
    for (int a = 0; a < 3; ++a)
      on_plane |= m.node_lattice[key[0]][a] == 0 && m.node_lattice[key[1]][a] == 0 && m.node_lattice[key[2]][a] == 0;
    if (on_plane) continue;
    const uint8_t mark = cavity.count(key) ? 1 : 2;
    for (int32_t n : key) side[n] |= mark;
  }

  SolveOptions so;
  so.method = SolverMethod::Static;
  so.forces.pressure_pa = units::mmhg_to_pa(o.pressure_mmhg) * o.solve_fraction;
  so.residual_tolerance = o.residual_tolerance;
  so.max_steps = 500000;
  const SolveResult r = solve(m, so);

  LameResult out;
  out.options = o;
  // Means over the whole sphere's boundary nodes: an off-plane node of the octant stands for 8 mirror
  // images, a node on one symmetry plane for 4, on two for 2: weight ½ per plane it lies on, so the
  // octant's mean equals the whole sphere's (checked against a full-sphere model: same values).
  double sum_in = 0, sum_out = 0, w_in = 0, w_out = 0;
  for (int64_t i = 0; i < m.node_count(); ++i) {
    if (!side[i]) continue;
    const Vec3 radial = m.rest_m[i].normalized();
    const double u = (r.x[i] - m.rest_m[i]).dot(radial) / o.solve_fraction;
    double w = 1.0;
    for (int a = 0; a < 3; ++a)
      if (m.node_lattice[i][a] == 0) w *= 0.5;
    if (side[i] & 1) { sum_in += w * u; w_in += w; ++out.inner_nodes; }
    if (side[i] & 2) { sum_out += w * u; w_out += w; ++out.outer_nodes; }
  }
  out.u_inner_mm = units::m_to_mm(sum_in / std::max(w_in, 1e-300));
  out.u_outer_mm = units::m_to_mm(sum_out / std::max(w_out, 1e-300));
  const double a = o.inner_mm, b = o.outer_mm, p = units::mmhg_to_pa(o.pressure_mmhg) * 1e-3;   // p in kPa·… mm
  // In mm with E in kPa and p in kPa: u comes out in mm.
  const double Ek = o.young_kpa;
  out.u_inner_analytic_mm = lame_sphere_u(a, a, b, p, Ek / 1.5, Ek / 2.5);   // ν = 1/4: K = E/1.5, G = E/2.5
  out.u_outer_analytic_mm = lame_sphere_u(b, a, b, p, Ek / 1.5, Ek / 2.5);
  out.u_inner_lattice_mm = lame_sphere_u(a, a, b, p, 0.721 * Ek, 0.432 * Ek);   // §4 lattice moduli
  out.u_outer_lattice_mm = lame_sphere_u(b, a, b, p, 0.721 * Ek, 0.432 * Ek);
  out.rel_error_inner = out.u_inner_mm / out.u_inner_analytic_mm - 1.0;
  out.rel_error_outer = out.u_outer_mm / out.u_outer_analytic_mm - 1.0;
  out.rel_error_inner_lattice = out.u_inner_mm / out.u_inner_lattice_mm - 1.0;
  out.rel_error_outer_lattice = out.u_outer_mm / out.u_outer_lattice_mm - 1.0;
  out.nodes = m.node_count();
  out.steps = r.steps;
  out.residual = r.residual;
  out.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return out;
}

nlohmann::json to_json(const LameResult& r) {
  return {{"cube_mm", r.options.cube_mm},
          {"voxel_mm", r.options.voxel_mm > 0 ? r.options.voxel_mm : r.options.cube_mm},
          {"inner_radius_mm", r.options.inner_mm},
          {"outer_radius_mm", r.options.outer_mm},
          {"young_kpa", r.options.young_kpa},
          {"pressure_mmhg", r.options.pressure_mmhg},
          {"solved_at_mmhg", r.options.pressure_mmhg * r.options.solve_fraction},
          {"u_inner_mm", r.u_inner_mm},
          {"u_outer_mm", r.u_outer_mm},
          {"u_inner_analytic_mm", r.u_inner_analytic_mm},
          {"u_outer_analytic_mm", r.u_outer_analytic_mm},
          {"rel_error_inner", r.rel_error_inner},
          {"rel_error_outer", r.rel_error_outer},
          {"lattice_bulk_over_e", 0.721},
          {"lattice_shear_over_e", 0.432},
          {"u_inner_lattice_mm", r.u_inner_lattice_mm},
          {"u_outer_lattice_mm", r.u_outer_lattice_mm},
          {"rel_error_inner_lattice", r.rel_error_inner_lattice},
          {"rel_error_outer_lattice", r.rel_error_outer_lattice},
          {"nodes", r.nodes},
          {"inner_nodes", r.inner_nodes},
          {"outer_nodes", r.outer_nodes},
          {"steps", r.steps},
          {"residual", r.residual},
          {"wall_time_s", r.wall_time_s}};
}

}  // namespace pneumo
