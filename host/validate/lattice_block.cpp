// The lattice's effective Young's modulus along an axis (method.md §4): 1.140·E·(1 − 0.063/n) for a
// block n cubes across with free sides. This catches the 4.8× pitfall (one k per spring from its own
// length, without Lloyd's sum over tetrahedra).
#include <cmath>

#include "core/units.h"
#include "solve/solve_on_device.h"
#include "validate/validate.h"

namespace pneumo {

LatticeResult validate_lattice(int n, double cube_mm) {
  if (n < 4 || n % 2) throw std::invalid_argument("validate_lattice: cubes_across must be even and at least 4");
  const double E = 60e3;                       // Pa; the ratio does not depend on it
  const double strain = 1e-4;                  // small: linear elasticity
  Geometry g;
  g.dims = {n, n, 2 * n};
  g.spacing_mm = Vec3::Constant(cube_mm);
  g.origin_mm = Vec3::Constant(0.5 * cube_mm);   // nodes at multiples of the cube size
  std::vector<Role> roles(g.voxel_count(), Role::Wall);
  MeshOptions mo;
  mo.cube_voxels = 1;
  mo.model = MeshModel::Wall;
  Mesh m = build_mesh(VoxelRoles{g, roles.data(), nullptr}, mo, [&](Role, int) { return E; });
  assign_material(m, MaterialOptions{});

  const double h = units::mm_to_m(cube_mm), length = 2 * n * h;
  std::vector<Vec3> x = m.rest_m;
  for (int64_t i = 0; i < m.node_count(); ++i) {
    const auto& l = m.node_lattice[i];
    if (l[2] == 0) m.hold[i] |= kHoldZ;
    if (l[2] == 2 * n) { m.hold[i] |= kHoldZ; x[i][2] += strain * length; }
    if (l[2] == 0 && l[1] == 0 && l[0] == 0) m.hold[i] = kHoldAll;   // no rigid translation
    if (l[2] == 0 && l[1] == 0 && l[0] == n) m.hold[i] |= kHoldY;    // no rigid rotation about z
  }
  SolveOptions so;
  so.method = SolverMethod::Static;
  so.residual_tolerance = 1e-7;
  so.max_steps = 200000;
  so.progress = false;
  const SolveResult r = solve_on_device(nullptr, m, so, x);   // the CPU: the check of the lattice itself

  ForceEvaluator eval(m);
  std::vector<Vec3> f;
  eval.evaluate(ForceModel{}, r.x, {}, f);
  double reaction = 0.0, z_quarter = 0.0, z_three_quarters = 0.0;
  int n1 = 0, n3 = 0;
  for (int64_t i = 0; i < m.node_count(); ++i) {
    const int c = m.node_lattice[i][2];
    if (c == 2 * n) reaction -= f[i][2];   // the load the holds apply to the top face
    if (c == n / 2) { z_quarter += r.x[i][2]; ++n1; }
    if (c == 3 * n / 2) { z_three_quarters += r.x[i][2]; ++n3; }
  }
  const double gauge = n * h;
  const double measured_strain = (z_three_quarters / n3 - z_quarter / n1 - gauge) / gauge;
  const double stress = reaction / ((n * h) * (n * h));
  LatticeResult out;
  out.cubes_across = n;
  out.young_ratio_raw = stress / measured_strain / E;
  out.young_ratio_axis = out.young_ratio_raw / (1.0 - 0.063 / n);
  out.steps = r.steps;
  out.residual = r.residual;
  return out;
}

nlohmann::json to_json(const LatticeResult& r) {
  return {{"cubes_across", r.cubes_across}, {"young_ratio_raw", r.young_ratio_raw},
          {"young_ratio_axis", r.young_ratio_axis}, {"young_ratio_axis_expected", r.expected_axis},
          {"rel_error", r.young_ratio_axis / r.expected_axis - 1.0}, {"steps", r.steps}, {"residual", r.residual}};
}

}  // namespace pneumo
