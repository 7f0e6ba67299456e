#include "validate/tet_field.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace pneumo {

namespace {
int64_t cube_key(const std::array<int64_t, 3>& c) {
  return ((c[2] + (1 << 20)) << 42) | ((c[1] + (1 << 20)) << 21) | (c[0] + (1 << 20));
}
}  // namespace

TetField::TetField(const Mesh& m, double cube_m) : m_(m), cube_m_(cube_m) {
  if (m.node_count() == 0) throw std::logic_error("TetField: an empty mesh");
  origin_ = m.rest_m[0] - Vec3(m.node_lattice[0][0], m.node_lattice[0][1], m.node_lattice[0][2]) * cube_m;
  for (std::size_t t = 0; t < m.tets.size(); ++t) {
    Vec3 c = Vec3::Zero();
    for (int32_t n : m.tets[t]) c += 0.25 * m.rest_m[n];
    by_cube_[cube_key(cell(c))].push_back(int32_t(t));
  }
}

Vec3 TetField::at(const Vec3& p, const std::vector<Vec3>& u, bool& outside) const {
  const std::array<int64_t, 3> c = cell(p);
  int32_t best = -1;
  std::array<double, 4> best_w{};
  double best_min = -HUGE_VAL;
  auto consider = [&](const std::array<int64_t, 3>& q) {
    const auto it = by_cube_.find(cube_key(q));
    if (it == by_cube_.end()) return;
    for (int32_t t : it->second) {
      const std::array<double, 4> w = weights(t, p);
      const double lo = *std::min_element(w.begin(), w.end());
      if (lo > best_min) {
        best_min = lo;
        best = t;
        best_w = w;
      }
    }
  };
  consider(c);
  outside = best < 0;
  for (int dz = -1; dz <= 1 && best < 0; ++dz)   // then the 26 neighbours together
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx)
        if (dx || dy || dz) consider({c[0] + dx, c[1] + dy, c[2] + dz});
  if (best < 0) throw std::logic_error("TetField: a point more than a cube from the mesh");
  Vec3 v = Vec3::Zero();
  for (int i = 0; i < 4; ++i) v += best_w[i] * u[m_.tets[best][i]];
  return v;
}

std::array<int64_t, 3> TetField::cell(const Vec3& p) const {
  const Vec3 q = (p - origin_) / cube_m_;
  return {int64_t(std::floor(q[0])), int64_t(std::floor(q[1])), int64_t(std::floor(q[2]))};
}

std::array<double, 4> TetField::weights(int32_t t, const Vec3& p) const {
  const auto& q = m_.tets[t];
  Mat3 D;
  for (int i = 0; i < 3; ++i) D.col(i) = m_.rest_m[q[i + 1]] - m_.rest_m[q[0]];
  const Vec3 l = D.inverse() * (p - m_.rest_m[q[0]]);
  return {1.0 - l.sum(), l[0], l[1], l[2]};
}

std::vector<Vec3> fibonacci_sphere(int n) {
  std::vector<Vec3> d(n);
  const double golden = M_PI * (3.0 - std::sqrt(5.0));
  for (int i = 0; i < n; ++i) {
    const double z = 1.0 - (2.0 * i + 1.0) / n, r = std::sqrt(1.0 - z * z);
    d[i] = Vec3(r * std::cos(golden * i), r * std::sin(golden * i), z);
  }
  return d;
}

}  // namespace pneumo
