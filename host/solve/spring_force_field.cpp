// The springs of method.md §5 (forces.h) as a ForceField, with their exact stiffness for Newton.
//
// A nonlinear spring (a, b) with d = x_a − x_b, l = |d|, d̂ = d/l carries the tension T(l) = k·l₀·g(ε)
// (stiffened_strain; g = ε for b = 0); its Hessian block is K_aa = T'(l) d̂d̂ᵀ + (T/l)(I − d̂d̂ᵀ) with
// T' = k·g'(ε), and K_ab = −K_aa. Nimura's linear spring has K_aa = k·I. Kitasaka's volume term
// U = ½ k_v f V₀ s², s = (V − V₀)/V₀, has K = (k_v f/V₀) ∇V ∇Vᵀ + k_v f s ∇²V.
#include <cmath>

#include "solve/force_field.h"
#include "solve/solver_common.h"

namespace pneumo {

namespace {

class SpringForceField final : public ForceField {
 public:
  explicit SpringForceField(const Mesh& m) : m_(m), eval_(m) {}

  void evaluate(const ForceModel& model, const std::vector<Vec3>& x, const std::vector<Vec3>& v,
                std::vector<Vec3>& f) override {
    eval_.evaluate(model, x, v, f);
  }

  std::vector<double> fire_masses(const ForceModel& model) override { return detail::fire_masses(m_, model); }

  double elastic_energy(const ForceModel& model, const std::vector<Vec3>& x) override {
    return spring_energy(m_, x, model.spring_model, model.stiffening) +
           (model.volume_stiffness_pa != 0.0 ? volume_energy(m_, x, model.volume_stiffness_pa) : 0.0);
  }

  void linearize(const ForceModel& model, const std::vector<Vec3>& x) override {
    const int64_t S = int64_t(m_.springs.size());
    block_.resize(S);
#pragma omp parallel for schedule(static) if (S > 20000)
    for (int64_t s = 0; s < S; ++s) {
      const int32_t a = m_.springs[s][0], b = m_.springs[s][1];
      const double k = m_.spring_k[s];
      if (model.spring_model == SpringModel::Linear) { block_[s] = k * Mat3::Identity(); continue; }
      const Vec3 d = x[a] - x[b];
      const double l = d.norm(), l0 = m_.spring_rest_m[s];
      if (!(l > 0.0)) { block_[s] = k * Mat3::Identity(); continue; }
      const Vec3 n = d / l;
      const double eps = (l - l0) / l0;
      const bool stiffens = model.stiffening > 0.0 && eps > 0.0;
      const double tension = k * l0 * stiffened_strain(eps, model.stiffening);
      const double slope = stiffens ? k * std::exp(model.stiffening * eps) : k;
      const Mat3 nn = n * n.transpose();
      block_[s] = slope * nn + (tension / l) * (Mat3::Identity() - nn);
    }
    volume_stiffness_pa_ = model.volume_stiffness_pa;
    if (volume_stiffness_pa_ != 0.0) x_ = x;
  }

  void stiffness_product(const std::vector<Vec3>& p, std::vector<Vec3>& kp) override {
    const Adjacency& adj = eval_.adjacency();
    const int64_t N = m_.node_count(), T = int64_t(m_.tets.size());
    if (volume_stiffness_pa_ != 0.0) {
      tet_kp_.resize(4 * T);
#pragma omp parallel for schedule(static) if (T > 20000)
      for (int64_t t = 0; t < T; ++t) volume_product(t, p, &tet_kp_[4 * t]);
    }
    kp.resize(N);
#pragma omp parallel for schedule(static) if (N > 20000)
    for (int64_t n = 0; n < N; ++n) {
      Vec3 sum = Vec3::Zero();
      for (int64_t e = adj.springs.begin(n); e < adj.springs.end(n); ++e) {
        const int32_t it = adj.springs.item[e];
        const int32_t s = it / 8, other = m_.springs[s][it % 8 == 0 ? 1 : 0];
        sum += block_[s] * (p[n] - p[other]);
      }
      if (volume_stiffness_pa_ != 0.0)
        for (int64_t e = adj.tets.begin(n); e < adj.tets.end(n); ++e) {
          const int32_t it = adj.tets.item[e];
          sum += tet_kp_[4 * (it / 8) + it % 8];
        }
      kp[n] = sum;
    }
  }

  void stiffness_diagonal(std::vector<Mat3>& blocks) override {
    blocks.assign(m_.node_count(), Mat3::Zero());
    for (std::size_t s = 0; s < m_.springs.size(); ++s)
      for (int32_t n : m_.springs[s]) blocks[n] += block_[s];
    if (volume_stiffness_pa_ != 0.0)
      for (std::size_t t = 0; t < m_.tets.size(); ++t) {
        // The Gauss–Newton part only: ∇²V has no diagonal block (it is linear in each vertex apart).
        const auto& q = m_.tets[t];
        const auto g = tet_volume_gradient(x_[q[0]], x_[q[1]], x_[q[2]], x_[q[3]]);
        const double c = volume_stiffness_pa_ * m_.tet_fraction[t] / m_.tet_rest_volume_m3[t];
        for (int i = 0; i < 4; ++i) blocks[q[i]] += c * g[i] * g[i].transpose();
      }
  }

  int64_t evaluations() const override { return eval_.evaluations(); }

 private:
  // K p on the four vertices of tetrahedron t from the volume term.
  void volume_product(int64_t t, const std::vector<Vec3>& p, Vec3* out) const {
    const auto& q = m_.tets[t];
    const Vec3 &a = x_[q[0]], &b = x_[q[1]], &c = x_[q[2]], &d = x_[q[3]];
    const Vec3 &pa = p[q[0]], &pb = p[q[1]], &pc = p[q[2]], &pd = p[q[3]];
    const auto g = tet_volume_gradient(a, b, c, d);
    const double v0 = m_.tet_rest_volume_m3[t], kv = volume_stiffness_pa_ * m_.tet_fraction[t];
    const double s = (signed_tet_volume(a, b, c, d) - v0) / v0;
    double dv = 0.0;
    for (int i = 0; i < 4; ++i) dv += g[i].dot(p[q[i]]);
    // δ(∇V) along p, from the cross products of tet_volume_gradient.
    std::array<Vec3, 4> dg;
    dg[1] = ((pc - pa).cross(d - a) + (c - a).cross(pd - pa)) / 6.0;
    dg[2] = ((pd - pa).cross(b - a) + (d - a).cross(pb - pa)) / 6.0;
    dg[3] = ((pb - pa).cross(c - a) + (b - a).cross(pc - pa)) / 6.0;
    dg[0] = -(dg[1] + dg[2] + dg[3]);
    for (int i = 0; i < 4; ++i) out[i] = kv / v0 * dv * g[i] + kv * s * dg[i];
  }

  const Mesh& m_;
  ForceEvaluator eval_;
  std::vector<Mat3> block_;
  std::vector<Vec3> x_, tet_kp_;
  double volume_stiffness_pa_ = 0.0;
};

}  // namespace

std::unique_ptr<ForceField> make_spring_force_field(const Mesh& m) { return std::make_unique<SpringForceField>(m); }

}  // namespace pneumo
