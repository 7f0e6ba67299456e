#include "solve/fem_tets.h"

#include <algorithm>
#include <numeric>

namespace pneumo {

FemLaw fem_law_of(MaterialModel m) { return m == MaterialModel::FemNeoHookean ? FemLaw::NeoHookean : FemLaw::Corotational; }

FemTets::FemTets(const Mesh& m, FemLaw l) : law(l) {
  const int64_t T = int64_t(m.tets.size());
  rest.resize(T);
  material.resize(T);
  kappa.resize(T);
  for (int64_t t = 0; t < T; ++t) {
    const auto& q = m.tets[t];
    rest[t] = tet_rest(m.rest_m[q[0]], m.rest_m[q[1]], m.rest_m[q[2]], m.rest_m[q[3]]);
    const double nu = m.tet_poisson.empty() ? 0.25 : m.tet_poisson[t];
    material[t] = TetMaterial::from_young_poisson(m.tet_young_pa[t], nu);
    if (!m.tet_fibre_k1_pa.empty() && m.tet_fibre_k1_pa[t] > 0.0) {
      material[t].fibre = m.tet_fibre[t];
      material[t].fibre_k1_pa = m.tet_fibre_k1_pa[t];
      material[t].fibre_k2 = m.fibre_k2;
    }
    kappa[t] = volumetric_modulus(law, material[t]);
  }
}

FemGroups::FemGroups(const Mesh& m, const FemTets& ft, bool mean_dilatation) : by_cube(mean_dilatation) {
  const int64_t T = int64_t(m.tets.size());
  tets.resize(T);
  std::iota(tets.begin(), tets.end(), 0);
  auto key = [&](int32_t t) { return mean_dilatation ? m.tet_cube[t] * 2 + int64_t(m.tet_part[t]) : int64_t(t); };
  std::stable_sort(tets.begin(), tets.end(), [&](int32_t a, int32_t b) { return key(a) < key(b); });
  group_of_tet.assign(T, 0);
  for (int64_t i = 0; i < T; ++i) {
    if (i == 0 || key(tets[i]) != key(tets[i - 1])) begin.push_back(int32_t(i));
    group_of_tet[tets[i]] = int32_t(begin.size() - 1);
  }
  begin.push_back(int32_t(T));
  weight.assign(begin.size() - 1, 0.0);
  for (int64_t t = 0; t < T; ++t) weight[group_of_tet[t]] += ft.kappa[t] * ft.rest[t].volume_m3;
}

}  // namespace pneumo
