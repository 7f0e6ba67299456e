// The wall's circumferential fibres (wall_fibres.h).
#include "mesh/wall_fibres.h"

#include <cmath>
#include <map>

namespace pneumo {

namespace {
constexpr double kSlabM = 0.010;   // the body's axis is found per 10 mm of world z
int64_t slab_of(double z_m) { return int64_t(std::floor(z_m / kSlabM)); }
}  // namespace

std::vector<Vec3> circumferential_fibres(const Mesh& m, const std::vector<uint8_t>& fibrous) {
  // The body's axis per slab: the volume-weighted mean x, y of the tetrahedra whose centres lie in it
  // (both parts), so every tetrahedron's slab holds at least itself.
  const std::size_t T = m.tets.size();
  std::vector<Vec3> centre(T, Vec3::Zero());
  std::map<int64_t, std::pair<Vec3, double>> axis;
  for (std::size_t t = 0; t < T; ++t) {
    for (int32_t n : m.tets[t]) centre[t] += 0.25 * m.rest_m[n];
    const double w = m.tet_rest_volume_m3.empty() ? 1.0 : m.tet_rest_volume_m3[t];
    // Eigen leaves a default-constructed Vec3 uninitialised: insert zero.
    auto& a = axis.try_emplace(slab_of(centre[t][2]), Vec3::Zero(), 0.0).first->second;
    a.first += w * Vec3(centre[t][0], centre[t][1], 0.0);
    a.second += w;
  }
  std::vector<Vec3> fibre(T, Vec3::Zero());
  for (std::size_t t = 0; t < T; ++t) {
    if (t >= fibrous.size() || !fibrous[t]) continue;
    const auto& a = axis.at(slab_of(centre[t][2]));
    if (!(a.second > 0.0)) continue;
    const Vec3 r = Vec3(centre[t][0], centre[t][1], 0.0) - a.first / a.second;
    const double len = r.norm();
    if (len > 1e-9) fibre[t] = Vec3(-r[1], r[0], 0.0) / len;   // ẑ × r̂
  }
  return fibre;
}

void assign_wall_fibres(Mesh& m, const std::vector<uint8_t>& fibrous, double k1_over_mu, double k2) {
  m.tet_fibre = circumferential_fibres(m, fibrous);
  m.tet_fibre_k1_pa.assign(m.tets.size(), 0.0);
  m.fibre_k2 = k2;
  for (std::size_t t = 0; t < m.tets.size(); ++t) {
    if (m.tet_fibre[t].squaredNorm() == 0.0) continue;
    const double nu = m.tet_poisson.empty() ? 0.25 : m.tet_poisson[t];
    m.tet_fibre_k1_pa[t] = k1_over_mu * m.tet_young_pa[t] / (2.0 * (1.0 + nu));
  }
}

}  // namespace pneumo
