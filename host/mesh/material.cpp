// Node masses, spring stiffnesses and dampers (method.md §4; Lloyd et al. 2007 for ν = 1/4).
#include <cmath>

#include "mesh/mesh.h"

namespace pneumo {

double lloyd_tet_spring_k(double young_pa, double volume_m3) {
  // k_t = (2√2/25)·E_t·l_t with l_t = (6√2·V_t)^(1/3): the edge length of the regular tetrahedron
  // of the same volume. Summed over the tetrahedra sharing an edge (Nimura's printed Eq. 3 omits
  // the sum and makes the material ~4.8× too soft, §4).
  const double l = std::cbrt(6.0 * std::sqrt(2.0) * volume_m3);
  return 2.0 * std::sqrt(2.0) / 25.0 * young_pa * l;
}

std::vector<double> node_lloyd_stiffness(const Mesh& m) {
  std::vector<double> node_k(std::size_t(m.node_count()), 0.0);
  for (std::size_t t = 0; t < m.tets.size(); ++t) {
    const double k = lloyd_tet_spring_k(m.tet_young_pa[t], m.tet_rest_volume_m3[t]);
    for (int32_t n : m.tets[t]) node_k[std::size_t(n)] += k;
  }
  return node_k;
}

void assign_material(Mesh& m, const MaterialOptions& opt) {
  m.mass_kg.assign(m.node_count(), 0.0);
  m.spring_k.assign(m.springs.size(), 0.0);
  for (std::size_t t = 0; t < m.tets.size(); ++t) {
    const double v = m.tet_rest_volume_m3[t];
    // §4 with the tissue that fills the tetrahedron only (mesh.h): ρ f_t V_t / 4 per vertex.
    const double f = m.tet_fraction.empty() ? 1.0 : m.tet_fraction[t];
    for (int32_t n : m.tets[t]) m.mass_kg[n] += opt.density_kg_m3 * f * v / 4.0;
    const double k = opt.spring_scale * lloyd_tet_spring_k(m.tet_young_pa[t], v);
    for (int32_t s : m.tet_springs[t]) m.spring_k[s] += k;
  }
  m.spring_c.assign(m.springs.size(), 0.0);
  for (std::size_t s = 0; s < m.springs.size(); ++s) {
    // c = 2ζ√(m k), m the mean of the two node masses (§4).
    const double mass = 0.5 * (m.mass_kg[m.springs[s][0]] + m.mass_kg[m.springs[s][1]]);
    m.spring_c[s] = 2.0 * opt.damping_ratio * std::sqrt(mass * m.spring_k[s]);
  }
}

}  // namespace pneumo
