#include "solve/pressure_stiffness.h"

namespace pneumo {

namespace {
constexpr int kPairs[6][2] = {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}};
}

void PressureStiffness::linearize(const Mesh& m, const std::vector<Vec3>& x, double pressure_pa) {
  m_ = &m;
  u_.clear();
  if (pressure_pa == 0.0) return;
  const int64_t R = int64_t(m.load_tet.size());
  u_.resize(R);
#pragma omp parallel for schedule(static) if (R > 20000)
  for (int64_t l = 0; l < R; ++l) {
    const auto& q = m.tets[m.load_tet[l]];
    const Vec3 e1 = x[q[1]] - x[q[0]], e2 = x[q[2]] - x[q[0]], e3 = x[q[3]] - x[q[0]];
    Vec3 W[4][4];
    for (int i = 0; i < 4; ++i) {
      const Vec3& c = m.load_c[l][i];
      W[i][1] = c[1] * e3 - c[2] * e2;
      W[i][2] = c[2] * e1 - c[0] * e3;
      W[i][3] = c[0] * e2 - c[1] * e1;
      W[i][0] = -(W[i][1] + W[i][2] + W[i][3]);
    }
    for (int k = 0; k < 6; ++k) {
      const int i = kPairs[k][0], j = kPairs[k][1];
      u_[l][k] = 0.5 * pressure_pa * (W[i][j] - W[j][i]);
    }
  }
}

void PressureStiffness::add_product(const std::vector<Vec3>& p, std::vector<Vec3>& kp) const {
  // One thread, in load order: a few per cent of the elements, and the sum stays deterministic.
  for (std::size_t l = 0; l < u_.size(); ++l) {
    const auto& q = m_->tets[m_->load_tet[l]];
    for (int k = 0; k < 6; ++k) {
      const int i = kPairs[k][0], j = kPairs[k][1];
      kp[q[i]] += u_[l][k].cross(p[q[j]]);
      kp[q[j]] -= u_[l][k].cross(p[q[i]]);
    }
  }
}

}  // namespace pneumo
