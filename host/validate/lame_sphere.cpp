// Lamé's hollow sphere under internal pressure (method.md §10), meshed whole at several placements.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>


#include "core/error.h"
#include "core/units.h"
#include "solve/solve_on_device.h"
#include "validate/tet_field.h"
#include "validate/validate.h"

namespace pneumo {

double lame_sphere_u(double r, double a, double b, double p, double bulk, double shear) {
  return p * a * a * a / (b * b * b - a * a * a) * (r / (3.0 * bulk) + b * b * b / (4.0 * shear * r * r));
}

double lame_voxel_mm(const LameOptions& o) { return o.voxel_mm > 0.0 ? o.voxel_mm : 0.25 * o.cube_mm; }

Vec3 lame_placement(int k) {
  // Roberts' R3 low-discrepancy sequence: placements spread evenly over the cube, none on a symmetry
  // of the lattice (a node or a cube centre), where the staircase aligns with the sphere's axes.
  const double g = 1.2207440846057594754;   // the real root of g⁴ = g + 1
  const Vec3 alpha(1.0 / g, 1.0 / (g * g), 1.0 / (g * g * g));
  Vec3 o;
  for (int a = 0; a < 3; ++a) o[a] = std::fmod(0.5 + (k + 1) * alpha[a], 1.0);
  return o;
}

namespace {

constexpr int kSpherePoints = 8192;

struct PlacementMeans {
  double inner_sphere = 0, outer_sphere = 0;   // means over the true spheres r = a, r = b (mm)
  double inner_area = 0, outer_area = 0;   // means over the mesh's boundary (mm)
  double inner_node = 0, outer_node = 0;   // plain node means (mm)
  double inner_outside = 0, outer_outside = 0;   // share of the sphere's points outside the mesh
  int64_t nodes = 0, inner_nodes = 0, outer_nodes = 0, steps = 0;
  double residual = 0;
};

PlacementMeans solve_placement(const LameOptions& o, const Vec3& offset_cubes) {
  // The sphere is voxelised at voxel_mm (each voxel by its centre) and meshed with cubes of cube_mm,
  // exactly as the pipeline meshes a CT: a cube holding any shell voxel is a wall cube, its
  // tetrahedra weighted by the shell's share of their volume.
  const double v = lame_voxel_mm(o);
  const int L = int(std::lround(o.cube_mm / v));
  if (L < 1 || std::abs(L * v - o.cube_mm) > 1e-9 * o.cube_mm) {
    char what[160];
    std::snprintf(what, sizeof what, "validate lame-sphere: --cube-mm (%g) must be a whole multiple of --voxel-mm (%g)",
                  o.cube_mm, v);
    throw InputError(what);
  }
  const int64_t half = (int64_t(std::ceil(o.outer_mm / o.cube_mm)) + 1) * L;
  Geometry g;
  g.dims = {2 * half, 2 * half, 2 * half};
  g.spacing_mm = Vec3::Constant(v);
  // Lattice node (h, h, h) sits at −offset cubes from the sphere's centre (the world origin).
  g.origin_mm = Vec3::Constant(0.5 * v - half * v) - offset_cubes * o.cube_mm;
  std::vector<Role> roles(g.voxel_count());
#pragma omp parallel for schedule(static)
  for (int64_t k = 0; k < g.dims[2]; ++k)
    for (int64_t j = 0; j < g.dims[1]; ++j)
      for (int64_t i = 0; i < g.dims[0]; ++i) {
        const double r = g.to_world(Vec3(i, j, k)).norm();
        // Inside the cavity: "viscera" so that the wall's inner voxel faces carry the pressure.
        roles[g.linear_index(i, j, k)] = r < o.inner_mm ? Role::Viscera : r <= o.outer_mm ? Role::Wall : Role::Other;
      }
  MeshOptions mo;
  mo.cube_voxels = L;
  mo.model = MeshModel::Wall;
  const double E = units::kpa_to_pa(o.young_kpa);
  Mesh m = build_mesh(VoxelRoles{g, roles.data(), nullptr}, mo, [&](Role, int) { return E; });
  assign_material(m, MaterialOptions{});
  m.tet_poisson.assign(m.tets.size(), o.poisson);
  // Nothing is held: the pressure on the closed cavity has no net force, and a rigid drift has no
  // mean radial component over a closed surface.

  // Boundary triangles from the mesh itself: tetrahedron faces used once; those nearer the cavity
  // than the mid-radius are the inner surface, the rest the outer. Each node's share of its boundary's area (⅓ per triangle)
  // makes Σ A_i u_i / Σ A_i the exact surface mean of the piecewise-linear displacement.
  std::map<std::array<int32_t, 3>, int> face_uses;
  for (const auto& t : m.tets)
    for (int f = 0; f < 4; ++f) {
      std::array<int32_t, 3> key{t[(f + 1) % 4], t[(f + 2) % 4], t[(f + 3) % 4]};
      std::sort(key.begin(), key.end());
      ++face_uses[key];
    }
  const double mid_radius_m = units::mm_to_m(0.5 * (o.inner_mm + o.outer_mm));
  std::vector<double> area[2] = {std::vector<double>(m.node_count(), 0.0), std::vector<double>(m.node_count(), 0.0)};
  for (const auto& [key, uses] : face_uses) {
    if (uses != 1) continue;
    const double r = ((m.rest_m[key[0]] + m.rest_m[key[1]] + m.rest_m[key[2]]) / 3.0).norm();
    const int s = r < mid_radius_m ? 0 : 1;
    const double A = 0.5 * (m.rest_m[key[1]] - m.rest_m[key[0]]).cross(m.rest_m[key[2]] - m.rest_m[key[0]]).norm();
    for (int32_t n : key) area[s][n] += A / 3.0;
  }

  SolveOptions so;
  so.method = o.model == MaterialModel::Msd ? SolverMethod::Static : SolverMethod::Newton;
  so.forces.material = o.model;
  so.forces.mean_dilatation = o.mean_dilatation;
  so.forces.pressure_pa = units::mmhg_to_pa(o.pressure_mmhg) * o.solve_fraction;
  so.residual_tolerance = o.residual_tolerance;
  so.max_steps = 500000;
  std::shared_ptr<ocl::Context> ctx;
  if (const ocl::DeviceSpec spec = ocl::parse_device_spec(o.device); spec.use_opencl) ctx = ocl::Context::shared(spec);
  const SolveResult r = solve_on_device(ctx.get(), m, so);

  PlacementMeans out;
  double sum_a[2] = {0, 0}, w_a[2] = {0, 0}, sum_n[2] = {0, 0};
  int64_t count[2] = {0, 0};
  for (int64_t i = 0; i < m.node_count(); ++i)
    for (int s = 0; s < 2; ++s) {
      if (area[s][i] == 0.0) continue;
      const double u_mm = units::m_to_mm((r.x[i] - m.rest_m[i]).dot(m.rest_m[i].normalized())) / o.solve_fraction;
      sum_a[s] += area[s][i] * u_mm;
      w_a[s] += area[s][i];
      sum_n[s] += u_mm;
      ++count[s];
    }
  // The closed form describes the true spheres: the field there, radial component, mean over the
  // lattice's points (the finite cell method's boundary lies inside the cut cubes, not at their nodes).
  {
    std::vector<Vec3> u(m.node_count());
    for (int64_t i = 0; i < m.node_count(); ++i) u[i] = r.x[i] - m.rest_m[i];
    const TetField field(m, units::mm_to_m(o.cube_mm));
    const std::vector<Vec3> dirs = fibonacci_sphere(kSpherePoints);
    for (int s = 0; s < 2; ++s) {
      const double radius_m = units::mm_to_m(s == 0 ? o.inner_mm : o.outer_mm);
      double sum = 0.0;
      int outside = 0;
      for (const Vec3& d : dirs) {
        bool out_of_mesh = false;
        sum += field.at(radius_m * d, u, out_of_mesh).dot(d);
        outside += out_of_mesh;
      }
      (s == 0 ? out.inner_sphere : out.outer_sphere) = units::m_to_mm(sum / dirs.size()) / o.solve_fraction;
      (s == 0 ? out.inner_outside : out.outer_outside) = double(outside) / dirs.size();
    }
  }
  out.inner_area = sum_a[0] / std::max(w_a[0], 1e-300);
  out.outer_area = sum_a[1] / std::max(w_a[1], 1e-300);
  out.inner_node = sum_n[0] / std::max<int64_t>(count[0], 1);
  out.outer_node = sum_n[1] / std::max<int64_t>(count[1], 1);
  out.nodes = m.node_count();
  out.inner_nodes = count[0];
  out.outer_nodes = count[1];
  out.steps = r.steps;
  out.residual = r.residual;
  return out;
}

}  // namespace

LameResult validate_lame_sphere(const LameOptions& o) {
  if (o.placements < 1) throw std::invalid_argument("validate_lame_sphere: placements must be at least 1");
  const auto t0 = std::chrono::steady_clock::now();
  LameResult out;
  out.options = o;
  out.u_inner_min_mm = out.u_outer_min_mm = HUGE_VAL;
  out.u_inner_max_mm = out.u_outer_max_mm = -HUGE_VAL;
  for (int k = 0; k < o.placements; ++k) {
    const PlacementMeans p = solve_placement(o, lame_placement(k));
    out.u_inner_mm += p.inner_sphere / o.placements;
    out.u_outer_mm += p.outer_sphere / o.placements;
    out.u_inner_boundary_mm += p.inner_area / o.placements;
    out.u_outer_boundary_mm += p.outer_area / o.placements;
    out.inner_points_outside += p.inner_outside / o.placements;
    out.outer_points_outside += p.outer_outside / o.placements;
    out.u_inner_node_mean_mm += p.inner_node / o.placements;
    out.u_outer_node_mean_mm += p.outer_node / o.placements;
    out.u_inner_min_mm = std::min(out.u_inner_min_mm, p.inner_sphere);
    out.u_inner_max_mm = std::max(out.u_inner_max_mm, p.inner_sphere);
    out.u_outer_min_mm = std::min(out.u_outer_min_mm, p.outer_sphere);
    out.u_outer_max_mm = std::max(out.u_outer_max_mm, p.outer_sphere);
    out.nodes = std::max(out.nodes, p.nodes);
    out.inner_nodes = std::max(out.inner_nodes, p.inner_nodes);
    out.outer_nodes = std::max(out.outer_nodes, p.outer_nodes);
    out.steps = std::max(out.steps, p.steps);
    out.residual = std::max(out.residual, p.residual);
  }
  const double a = o.inner_mm, b = o.outer_mm;
  const double p = units::mmhg_to_pa(o.pressure_mmhg) * 1e-3;   // kPa, with E in kPa and radii in mm: u in mm
  const double Ek = o.young_kpa;
  // The springs' ν is 1/4 (K = E/1.5, G = E/2.5) and their lattice moduli those of §4; the finite
  // elements' are the nominal K = E/(3(1 − 2ν)), G = E/(2(1 + ν)).
  const bool springs = o.model == MaterialModel::Msd;
  const double nu = springs ? 0.25 : o.poisson;
  const double K = Ek / (3.0 * (1.0 - 2.0 * nu)), G = Ek / (2.0 * (1.0 + nu));
  const double K_model = springs ? 0.721 * Ek : K, G_model = springs ? 0.432 * Ek : G;
  out.u_inner_analytic_mm = lame_sphere_u(a, a, b, p, K, G);
  out.u_outer_analytic_mm = lame_sphere_u(b, a, b, p, K, G);
  out.u_inner_lattice_mm = lame_sphere_u(a, a, b, p, K_model, G_model);
  out.u_outer_lattice_mm = lame_sphere_u(b, a, b, p, K_model, G_model);
  out.rel_error_inner = out.u_inner_mm / out.u_inner_analytic_mm - 1.0;
  out.rel_error_outer = out.u_outer_mm / out.u_outer_analytic_mm - 1.0;
  out.rel_error_inner_lattice = out.u_inner_mm / out.u_inner_lattice_mm - 1.0;
  out.rel_error_outer_lattice = out.u_outer_mm / out.u_outer_lattice_mm - 1.0;
  out.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return out;
}

nlohmann::json to_json(const LameResult& r) {
  return {{"model", enum_name(r.options.model)},
          {"device", r.options.device},
          {"poisson_ratio", r.options.model == MaterialModel::Msd ? 0.25 : r.options.poisson},
          {"mean_dilatation", r.options.mean_dilatation},
          {"cube_mm", r.options.cube_mm},
          {"voxel_mm", lame_voxel_mm(r.options)},
          {"inner_radius_mm", r.options.inner_mm},
          {"outer_radius_mm", r.options.outer_mm},
          {"young_kpa", r.options.young_kpa},
          {"pressure_mmhg", r.options.pressure_mmhg},
          {"solved_at_mmhg", r.options.pressure_mmhg * r.options.solve_fraction},
          {"placements", r.options.placements},
          {"u_inner_mm", r.u_inner_mm},
          {"u_outer_mm", r.u_outer_mm},
          {"u_inner_analytic_mm", r.u_inner_analytic_mm},
          {"u_outer_analytic_mm", r.u_outer_analytic_mm},
          {"rel_error_inner", r.rel_error_inner},
          {"rel_error_outer", r.rel_error_outer},
          {"lattice_bulk_over_e", r.options.model == MaterialModel::Msd ? nlohmann::json(0.721) : nlohmann::json(nullptr)},
          {"lattice_shear_over_e", r.options.model == MaterialModel::Msd ? nlohmann::json(0.432) : nlohmann::json(nullptr)},
          {"u_inner_lattice_mm", r.u_inner_lattice_mm},
          {"u_outer_lattice_mm", r.u_outer_lattice_mm},
          {"rel_error_inner_lattice", r.rel_error_inner_lattice},
          {"rel_error_outer_lattice", r.rel_error_outer_lattice},
          {"u_inner_boundary_mm", r.u_inner_boundary_mm},
          {"u_outer_boundary_mm", r.u_outer_boundary_mm},
          {"inner_points_outside_mesh", r.inner_points_outside},
          {"outer_points_outside_mesh", r.outer_points_outside},
          {"u_inner_range_mm", {r.u_inner_min_mm, r.u_inner_max_mm}},
          {"u_outer_range_mm", {r.u_outer_min_mm, r.u_outer_max_mm}},
          {"u_inner_node_mean_mm", r.u_inner_node_mean_mm},
          {"u_outer_node_mean_mm", r.u_outer_node_mean_mm},
          {"nodes", r.nodes},
          {"inner_nodes", r.inner_nodes},
          {"outer_nodes", r.outer_nodes},
          {"steps", r.steps},
          {"residual", r.residual},
          {"wall_time_s", r.wall_time_s}};
}

}  // namespace pneumo
