// The same mesh at another rest shape (gravity compensation, solve/gravity_compensation.h).
#include <string>

#include "core/error.h"
#include "mesh/mesh.h"

namespace pneumo {

Mesh with_rest_shape(const Mesh& m, const std::vector<Vec3>& rest_m) {
  if (rest_m.size() != m.rest_m.size())
    throw std::invalid_argument("with_rest_shape: " + std::to_string(rest_m.size()) + " positions for " +
                                std::to_string(m.rest_m.size()) + " nodes");
  Mesh r = m;
  r.rest_m = rest_m;
  for (std::size_t s = 0; s < r.springs.size(); ++s)
    r.spring_rest_m[s] = (rest_m[r.springs[s][0]] - rest_m[r.springs[s][1]]).norm();
  int64_t inverted = 0;
  for (std::size_t t = 0; t < r.tets.size(); ++t) {
    const auto& q = r.tets[t];
    r.tet_rest_volume_m3[t] = signed_tet_volume(rest_m[q[0]], rest_m[q[1]], rest_m[q[2]], rest_m[q[3]]);
    inverted += !(r.tet_rest_volume_m3[t] > 0.0);
  }
  if (inverted > 0)
    throw std::runtime_error("with_rest_shape: " + std::to_string(inverted) + " of " + std::to_string(r.tets.size()) +
                             " tetrahedra are inside out in the new rest shape");
  return r;
}

}  // namespace pneumo
