#include "solve/interface_tie.h"

#include <algorithm>
#include <tuple>

#include "solve/force_field.h"
#include "solve/newton_linear_solver.h"

namespace pneumo {

namespace {

constexpr double kTieKappa = 10.0;   // interface_tie.h

class TiedForceField final : public ForceField {
 public:
  TiedForceField(const Mesh& m, std::vector<TiedPair> pairs, std::unique_ptr<ForceField> inner)
      : m_(m), pairs_(std::move(pairs)), inner_(std::move(inner)) {}

  void evaluate(const ForceModel& model, const std::vector<Vec3>& x, const std::vector<Vec3>& v,
                std::vector<Vec3>& f) override {
    inner_->evaluate(model, x, v, f);
    for (const TiedPair& p : pairs_) {
      const Vec3 force = p.stiffness_n_per_m * stretch(p, x);
      f[p.wall] -= force;
      f[p.viscera] += force;
    }
  }

  double elastic_energy(const ForceModel& model, const std::vector<Vec3>& x) override {
    double e = inner_->elastic_energy(model, x);
    for (const TiedPair& p : pairs_) e += 0.5 * p.stiffness_n_per_m * stretch(p, x).squaredNorm();
    return e;
  }

  void linearize(const ForceModel& model, const std::vector<Vec3>& x) override { inner_->linearize(model, x); }

  void stiffness_product(const std::vector<Vec3>& q, std::vector<Vec3>& kq) override {
    inner_->stiffness_product(q, kq);
    for (const TiedPair& p : pairs_) {
      const Vec3 d = p.stiffness_n_per_m * (q[p.wall] - q[p.viscera]);
      kq[p.wall] += d;
      kq[p.viscera] -= d;
    }
  }

  void stiffness_diagonal(std::vector<Mat3>& blocks) override {
    inner_->stiffness_diagonal(blocks);
    for (const TiedPair& p : pairs_) {
      blocks[p.wall] += p.stiffness_n_per_m * Mat3::Identity();
      blocks[p.viscera] += p.stiffness_n_per_m * Mat3::Identity();
    }
  }

  std::vector<double> fire_masses(const ForceModel& model) override {
    // Gershgorin (force_field.h): a pair adds k on the diagonal and −k off it to each row of both nodes.
    std::vector<double> mass = inner_->fire_masses(model);
    for (const TiedPair& p : pairs_) {
      mass[p.wall] += p.stiffness_n_per_m;
      mass[p.viscera] += p.stiffness_n_per_m;
    }
    return mass;
  }

  int64_t evaluations() const override { return inner_->evaluations(); }

  std::unique_ptr<NewtonLinearSolver> device_linear_solver(const std::vector<TiedPair>& ties) override {
    std::vector<TiedPair> all = ties;
    all.insert(all.end(), pairs_.begin(), pairs_.end());
    return inner_->device_linear_solver(all);
  }

 private:
  Vec3 stretch(const TiedPair& p, const std::vector<Vec3>& x) const {
    return (x[p.wall] - x[p.viscera]) - (m_.rest_m[p.wall] - m_.rest_m[p.viscera]);
  }
  const Mesh& m_;
  std::vector<TiedPair> pairs_;
  std::unique_ptr<ForceField> inner_;
};

}  // namespace

std::vector<TiedPair> interface_pairs(const Mesh& m, bool attached_only) {
  const std::vector<double> node_k = node_lloyd_stiffness(m);
  // Nodes sorted by lattice point, then part: a wall node followed by a viscera node at the same point is a pair.
  std::vector<int32_t> order(m.node_count());
  for (int32_t n = 0; n < int32_t(order.size()); ++n) order[n] = n;
  const auto key = [&](int32_t n) { return std::tuple(m.node_lattice[n], m.node_part[n]); };
  std::sort(order.begin(), order.end(), [&](int32_t a, int32_t b) { return key(a) < key(b); });
  std::vector<TiedPair> pairs;
  for (std::size_t i = 0; i + 1 < order.size(); ++i) {
    const int32_t a = order[i], b = order[i + 1];
    if (m.node_lattice[a] != m.node_lattice[b] || m.node_part[a] != Part::Wall || m.node_part[b] != Part::Viscera) continue;
    if (attached_only && (m.node_attached.empty() || !m.node_attached[a] || !m.node_attached[b])) continue;
    pairs.push_back({a, b, kTieKappa * std::max(node_k[a], node_k[b])});
  }
  return pairs;
}

std::unique_ptr<ForceField> with_interface_tie(const Mesh& m, const ForceModel& model, std::unique_ptr<ForceField> inner) {
  if (!model.tie_interface && !model.tie_attached) return inner;
  std::vector<TiedPair> pairs = interface_pairs(m, !model.tie_interface);
  if (pairs.empty()) return inner;
  return std::make_unique<TiedForceField>(m, std::move(pairs), std::move(inner));
}

}  // namespace pneumo
