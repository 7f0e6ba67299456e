// The gas pressure on the embedded cavity faces (mesh.h; method.md §5) and the volume they enclose.
#include "mesh/mesh.h"

namespace pneumo {

std::array<Vec3, 4> pressure_load_forces(const Mesh& m, int64_t l, const std::vector<Vec3>& x, double pressure_pa) {
  const auto& q = m.tets[m.load_tet[l]];
  const Vec3 e1 = x[q[1]] - x[q[0]], e2 = x[q[2]] - x[q[0]], e3 = x[q[3]] - x[q[0]];
  std::array<Vec3, 4> f;
  for (int i = 0; i < 4; ++i) f[i] = -pressure_pa * cofactor_times(e1, e2, e3, m.load_c[l][i]);
  return f;
}

double enclosed_cavity_volume(const Mesh& m, const std::vector<Vec3>& x, const Vec3& origin,
                              const std::optional<Vec3>& cut_normal) {
  // F(x) = s·P(x − origin), div F = s·tr P = 1: P = I, s = ⅓; or P = I − n nᵀ, s = ½.
  Mat3 sp = Mat3::Identity() / 3.0;
  if (cut_normal) sp = 0.5 * (Mat3::Identity() - *cut_normal * cut_normal->transpose());
  // Σ_faces F(x_f) · n da = Σ_i F(x_i) · cof(F) B_i = Σ_i F(x_i) · cof(D_s) c_i (F and the weights are linear).
  double v = 0.0;
  for (std::size_t l = 0; l < m.load_tet.size(); ++l) {
    const auto& q = m.tets[m.load_tet[l]];
    const Vec3 e1 = x[q[1]] - x[q[0]], e2 = x[q[2]] - x[q[0]], e3 = x[q[3]] - x[q[0]];
    for (int i = 0; i < 4; ++i) v -= (sp * (x[q[i]] - origin)).dot(cofactor_times(e1, e2, e3, m.load_c[l][i]));
  }
  return v;
}

std::vector<Vec3> pressure_forces(const Mesh& m, const std::vector<Vec3>& x, double pressure_pa) {
  std::vector<Vec3> f(x.size(), Vec3::Zero());
  for (std::size_t l = 0; l < m.load_tet.size(); ++l) {
    const auto fl = pressure_load_forces(m, int64_t(l), x, pressure_pa);
    const auto& q = m.tets[m.load_tet[l]];
    for (int i = 0; i < 4; ++i) f[q[i]] += fl[i];
  }
  return f;
}

}  // namespace pneumo
