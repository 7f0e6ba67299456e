#pragma once
// What a pressure load (mesh.h) carries, read back from the mesh for tests: its rest vectors
// B_i = Σ_faces w_i N dA (the forces at rest for a pressure of −1 Pa), its total area vector, and
// the area-weighted centroid of its faces.
#include <array>
#include <cstddef>

#include "mesh/mesh.h"

namespace pneumo {

inline std::array<Vec3, 4> load_b(const Mesh& m, std::size_t l) {
  return pressure_load_forces(m, int64_t(l), m.rest_m, -1.0);
}

/// Σ_faces N dA of load l (m², out of its solid).
inline Vec3 load_area_vector(const Mesh& m, std::size_t l) {
  const auto b = load_b(m, l);
  return b[0] + b[1] + b[2] + b[3];
}

/// Σ_faces A x_f / Σ A along the area vector's direction: the faces' centroid when they are parallel.
inline Vec3 load_centroid(const Mesh& m, std::size_t l) {
  const auto b = load_b(m, l);
  const Vec3 dir = load_area_vector(m, l).normalized();
  const auto& q = m.tets[m.load_tet[l]];
  Vec3 sum = Vec3::Zero();
  double w = 0.0;
  for (int i = 0; i < 4; ++i) {
    sum += b[i].dot(dir) * m.rest_m[q[i]];
    w += b[i].dot(dir);
  }
  return sum / w;
}

}  // namespace pneumo
