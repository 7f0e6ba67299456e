#include "solve/thorax_beyond_cut.h"

#include <cmath>
#include <stdexcept>

#include "solve/force_field.h"

namespace pneumo {

double thorax_volume_change_m3(const Mesh& m, const std::vector<Vec3>& x) {
  double dv = 0.0;
  for (std::size_t i = 0; i < m.thorax_node.size(); ++i)
    dv += m.thorax_area_m2[i].dot(x[m.thorax_node[i]] - m.rest_m[m.thorax_node[i]]);
  return dv;
}

namespace {

constexpr double kFaceKappa = 10.0;   // thorax_beyond_cut.h, as interface_tie.h's κ

class ThoraxForceField final : public ForceField {
 public:
  ThoraxForceField(const Mesh& m, std::unique_ptr<ForceField> inner)
      : m_(m), elastance_pa_per_m3_(1.0 / m.thorax_compliance_m3_per_pa), inner_(std::move(inner)) {
    const std::size_t n = m.thorax_node.size();
    double area = 0.0;
    for (const Vec3& a : m.thorax_area_m2) area += a.norm();
    area_m2_ = area;
    normal_ = m.thorax_area_m2.front().normalized();
    const std::vector<double> node_k = node_lloyd_stiffness(m);
    weight_.resize(n);
    k_.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
      weight_[i] = m.thorax_area_m2[i].norm() / area;
      k_[i] = kFaceKappa * node_k[std::size_t(m.thorax_node[i])];
      k_sum_ += k_[i];
    }
  }

  void evaluate(const ForceModel& model, const std::vector<Vec3>& x, const std::vector<Vec3>& v,
                std::vector<Vec3>& f) override {
    inner_->evaluate(model, x, v, f);
    add_product(x, &m_.rest_m, f, -1.0);
  }

  double elastic_energy(const ForceModel& model, const std::vector<Vec3>& x) override {
    const std::vector<double> s = normal_components(x, &m_.rest_m);
    const double mean = weighted_mean(s);
    double face = 0.0;
    for (std::size_t i = 0; i < s.size(); ++i) face += k_[i] * (s[i] - mean) * (s[i] - mean);
    const double dv = area_m2_ * mean;
    return inner_->elastic_energy(model, x) + 0.5 * elastance_pa_per_m3_ * dv * dv + 0.5 * face;
  }

  void linearize(const ForceModel& model, const std::vector<Vec3>& x) override { inner_->linearize(model, x); }

  void stiffness_product(const std::vector<Vec3>& q, std::vector<Vec3>& kq) override {
    inner_->stiffness_product(q, kq);
    add_product(q, nullptr, kq, 1.0);
  }

  // K_jj = a_j a_jᵀ / C + n nᵀ (k_j (1 − 2 w_j) + w_j² Σk): the diagonal of both terms' K.
  void stiffness_diagonal(std::vector<Mat3>& blocks) override {
    inner_->stiffness_diagonal(blocks);
    const Mat3 nn = normal_ * normal_.transpose();
    for (std::size_t j = 0; j < k_.size(); ++j) {
      const Vec3& a = m_.thorax_area_m2[j];
      blocks[std::size_t(m_.thorax_node[j])] +=
          elastance_pa_per_m3_ * a * a.transpose() + (k_[j] * (1.0 - 2.0 * weight_[j]) + weight_[j] * weight_[j] * k_sum_) * nn;
    }
  }

  // Gershgorin (force_field.h): row j of the chest's block sums |a_j|∞ Σ|a_i|₁ / C; the face's,
  // with K_jl = −k_j w_l − k_l w_j + w_j w_l Σk, at most 2 k_j + 2 w_j Σk.
  std::vector<double> fire_masses(const ForceModel& model) override {
    std::vector<double> mass = inner_->fire_masses(model);
    double sum = 0.0;
    for (const Vec3& a : m_.thorax_area_m2) sum += a.lpNorm<1>();
    for (std::size_t j = 0; j < k_.size(); ++j)
      mass[std::size_t(m_.thorax_node[j])] += 0.5 * elastance_pa_per_m3_ * m_.thorax_area_m2[j].lpNorm<Eigen::Infinity>() * sum +
                                             k_[j] + weight_[j] * k_sum_;
    return mass;
  }

  int64_t evaluations() const override { return inner_->evaluations(); }

  // The device's Newton holds no dense block: the host solves (newton_linear_solver.h), as with contact.

 private:
  /// n · (y_i − origin_i) over the face's nodes i: their normal displacements for y = x and origin the
  /// rest shape, or a direction's normal components for origin null.
  std::vector<double> normal_components(const std::vector<Vec3>& y, const std::vector<Vec3>* origin) const {
    std::vector<double> s(m_.thorax_node.size());
    for (std::size_t i = 0; i < s.size(); ++i) {
      const std::size_t n = std::size_t(m_.thorax_node[i]);
      s[i] = normal_.dot(origin ? Vec3(y[n] - (*origin)[n]) : y[n]);
    }
    return s;
  }
  double weighted_mean(const std::vector<double>& s) const {
    double mean = 0.0;
    for (std::size_t i = 0; i < s.size(); ++i) mean += weight_[i] * s[i];
    return mean;
  }
  /// out += sign · K (y − origin) over the face's nodes (normal_components): with y = x and the rest
  /// shape, minus the forces; with a direction and no origin, the stiffness product.
  void add_product(const std::vector<Vec3>& y, const std::vector<Vec3>* origin, std::vector<Vec3>& out, double sign) const {
    const std::vector<double> s = normal_components(y, origin);
    const double mean = weighted_mean(s);
    double k_r = 0.0;   // Σ k_i (s_i − s̄)
    for (std::size_t i = 0; i < s.size(); ++i) k_r += k_[i] * (s[i] - mean);
    const double pressure_pa = elastance_pa_per_m3_ * area_m2_ * mean;   // ΔV / C
    for (std::size_t j = 0; j < s.size(); ++j)
      out[std::size_t(m_.thorax_node[j])] +=
          sign * (pressure_pa * m_.thorax_area_m2[j] + (k_[j] * (s[j] - mean) - weight_[j] * k_r) * normal_);
  }

  const Mesh& m_;
  double elastance_pa_per_m3_;
  std::unique_ptr<ForceField> inner_;
  double area_m2_ = 0.0, k_sum_ = 0.0;
  Vec3 normal_ = Vec3::Zero();
  std::vector<double> weight_, k_;
};

}  // namespace

std::unique_ptr<ForceField> with_thorax_beyond_cut(const Mesh& m, std::unique_ptr<ForceField> inner) {
  if (m.thorax_node.empty()) return inner;
  if (!(m.thorax_compliance_m3_per_pa > 0.0))
    throw std::logic_error("with_thorax_beyond_cut: a cut face opens onto the chest, but its compliance is not set");
  return std::make_unique<ThoraxForceField>(m, std::move(inner));
}

}  // namespace pneumo
