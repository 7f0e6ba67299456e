#pragma once
// Helpers the force tests share: random states near rest, the largest nodal force, and the
// central-difference check that a force is minus the gradient of its energy.
#include <algorithm>
#include <random>
#include <vector>

#include "mesh/mesh.h"

namespace pneumo {
inline namespace mesh_test_support {

inline double max_norm(const std::vector<Vec3>& f) {
  double s = 0.0;
  for (const auto& v : f) s = std::max(s, v.norm());
  return s;
}

/// max over nodes of |f_i + ∂E/∂x_i|, the gradient by central differences of step delta: zero when f
/// is the force of the potential E.
template <class Energy>
double max_gradient_mismatch(const std::vector<Vec3>& x, const std::vector<Vec3>& f, double delta, Energy&& energy) {
  double worst = 0.0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    Vec3 grad;
    for (int a = 0; a < 3; ++a) {
      std::vector<Vec3> xp = x, xm = x;
      xp[i][a] += delta;
      xm[i][a] -= delta;
      grad[a] = (energy(xp) - energy(xm)) / (2 * delta);
    }
    worst = std::max(worst, (f[i] + grad).norm());
  }
  return worst;
}

inline std::vector<Vec3> perturbed(const Mesh& m, std::mt19937& rng, double amplitude_m) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<Vec3> x = m.rest_m;
  for (auto& p : x) p += amplitude_m * Vec3(u(rng), u(rng), u(rng));
  return x;
}

}  // namespace mesh_test_support
}  // namespace pneumo
