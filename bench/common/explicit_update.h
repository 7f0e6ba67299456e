#pragma once
// The plain symplectic Euler update of solve_explicit (v += dt·f/m, held axes zeroed, x += dt·v) in
// one parallel pass: what the benchmarks time as an explicit step beside the force evaluation.
#include <cstdint>
#include <vector>

#include "mesh/mesh.h"

namespace pneumo::bench {

inline void explicit_update(const Mesh& m, double dt, const std::vector<Vec3>& f, std::vector<Vec3>& x,
                            std::vector<Vec3>& v) {
  const int64_t n_nodes = m.node_count();
#pragma omp parallel for schedule(static)
  for (int64_t n = 0; n < n_nodes; ++n) {
    Vec3 vn = v[n] + (dt / m.mass_kg[n]) * f[n];
    if (const uint8_t h = m.hold[n])
      for (int a = 0; a < 3; ++a)
        if (h & (1 << a)) vn[a] = 0.0;
    v[n] = vn;
    x[n] += dt * vn;
  }
}

}  // namespace pneumo::bench
