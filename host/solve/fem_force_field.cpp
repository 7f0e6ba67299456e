// The tetrahedral finite elements (fem_element.h) as a ForceField: the CPU reference, double precision.
//
// Each tetrahedron t has Lamé's μ_t, λ_t from its Young's modulus (the Voigt average over the tissue
// that fills it, mesh.h) and its Poisson ratio, and the law's volumetric modulus κ_t. Against the
// volumetric locking of linear tetrahedra at ν → ½, the dilatation is averaged over the tetrahedra
// of one cube and part (a mean-dilatation or B-bar treatment, Nagtegaal et al. 1974; Hughes 1980):
// with the weights w_t = κ_t V_t and Λ_c = Σ w_t,
//   ē_c = Σ_t w_t e_t / Λ_c,   E_vol = ½ Λ_c ē_c²,
// so tetrahedron t feels the volumetric stress κ_t ē_c G_t instead of κ_t e_t G_t. A uniform strain
// has ē_c = e_t, so the patch test still holds; the deviatoric part stays per tetrahedron, so no
// zero-energy mode appears. With ForceModel::mean_dilatation = false each tetrahedron is its own group.
//
// The stiffness product for a direction p (δF_t = δD_s D_m⁻¹):
//   δP_t = δP_d,t + κ_t δē_c G_t + κ_t ē_c δG_t,   δē_c = Σ_s w_s (G_s : δF_s) / Λ_c,
// gathered as K p = V_t δP_t D_m⁻ᵀ per vertex (the nodal forces' derivative, sign flipped).
// That product is the reference; by default K is assembled once per linearisation instead
// (fem_stiffness_assembly.h) and each product is a sparse multiply, unless the matrix would take more
// than kAssembledBudgetBytes.
#include <algorithm>
#include <array>
#include <cmath>
#include <optional>
#include <stdexcept>

#include "core/log.h"
#include "solve/fem_element.h"
#include "solve/fem_stiffness_assembly.h"
#include "solve/fem_tets.h"
#include "solve/force_field.h"

namespace pneumo {

namespace {

// Above this bound the assembled K is not built and the product stays matrix-free. The bound counts
// each group's pairs apart (about 36 blocks per node where the upper triangle stores about 12), so
// meshes up to about 750 k nodes are assembled, in at most about 0.7 GB: every preset's mesh, and the
// 3 mm cubes of the convergence studies.
constexpr int64_t kAssembledBudgetBytes = int64_t(2) << 30;

class FemForceField final : public ForceField {
 public:
  FemForceField(const Mesh& m, FemLaw law, FemStiffness stiffness)
      : m_(m), law_(law), stiffness_(stiffness), adj_(Adjacency::of(m)), tets_(m, law) {}

  void evaluate(const ForceModel& model, const std::vector<Vec3>& x, const std::vector<Vec3>&,
                std::vector<Vec3>& f) override {
    // Velocities are not used: the finite elements carry no damping (the static and Newton solvers
    // need none).
    update_states(model, x);
    const int64_t T = int64_t(m_.tets.size()), R = int64_t(m_.load_tet.size()), N = m_.node_count();
    tet_f_.resize(4 * T);
#pragma omp parallel for schedule(static) if (T > 20000)
    for (int64_t t = 0; t < T; ++t) {
      const ElementState& s = state_[t];
      const Mat3 P = deviatoric_piola(s, tets_.material[t]) + tets_.kappa[t] * ebar_[groups_->group_of_tet[t]] * dilatation_gradient(s);
      const auto fe = nodal_forces(P, tets_.rest[t]);
      for (int i = 0; i < 4; ++i) tet_f_[4 * t + i] = fe[i];
    }
    load_f_.resize(model.pressure_pa != 0.0 ? 4 * R : 0);
    if (!load_f_.empty()) {
#pragma omp parallel for schedule(static) if (R > 20000)
      for (int64_t r = 0; r < R; ++r) {
        const auto fl = pressure_load_forces(m_, r, x, model.pressure_pa);
        for (int i = 0; i < 4; ++i) load_f_[4 * r + i] = fl[i];
      }
    }
    f.resize(N);
#pragma omp parallel for schedule(static) if (N > 20000)
    for (int64_t n = 0; n < N; ++n) {
      Vec3 sum = model.gravity_m_s2 * (m_.mass_kg.empty() ? 0.0 : m_.mass_kg[n]);
      sum += gather(adj_.tets, n, tet_f_);
      if (!load_f_.empty()) sum += gather(adj_.loads, n, load_f_);
      f[n] = sum;
    }
    ++evaluations_;
  }

  double elastic_energy(const ForceModel& model, const std::vector<Vec3>& x) override {
    update_states(model, x);
    double e = 0.0;
    for (std::size_t t = 0; t < m_.tets.size(); ++t) e += tets_.rest[t].volume_m3 * deviatoric_energy_density(state_[t], tets_.material[t]);
    for (std::size_t g = 0; g < ebar_.size(); ++g) e += 0.5 * groups_->weight[g] * ebar_[g] * ebar_[g];
    return e;
  }

  void linearize(const ForceModel& model, const std::vector<Vec3>& x) override {
    update_states(model, x);
    linear_x_ = x;
    linear_model_ = model;
    linear_version_ = states_version_;
    if (stiffness_ == FemStiffness::MatrixFree || assembled_current_) return;
    if (!assembly_) {
      assembly_ = FemStiffnessAssembly::within(m_, *groups_, kAssembledBudgetBytes);
      if (!assembly_) {
        stiffness_ = FemStiffness::MatrixFree;
        return;
      }
      const SymmetricBlockCsr& k = assembly_->matrix();
      log::debug("finite elements: stiffness assembled as " + std::to_string(k.col.size()) + " blocks for " +
                 std::to_string(m_.node_count()) + " nodes (" +
                 std::to_string(k.col.size() * (sizeof(Mat3) + sizeof(int32_t)) >> 20) + " MiB)");
    }
    assembly_->assemble(tets_, *groups_, state_, ebar_);
    assembled_current_ = true;
  }

  void stiffness_product(const std::vector<Vec3>& p, std::vector<Vec3>& kp) override {
    at_linearization();
    if (stiffness_ == FemStiffness::Assembled && assembled_current_) return assembly_->multiply(p, kp);
    const int64_t T = int64_t(m_.tets.size()), N = m_.node_count();
    dF_.resize(T);
#pragma omp parallel for schedule(static) if (T > 20000)
    for (int64_t t = 0; t < T; ++t) {
      const auto& q = m_.tets[t];
      dF_[t] = edge_matrix(p[q[0]], p[q[1]], p[q[2]], p[q[3]]) * tets_.rest[t].dm_inverse;
    }
    // δē_c from each tetrahedron's δe = G : δF.
    group_average([&](int32_t t) { return dilatation_gradient(state_[t]).cwiseProduct(dF_[t]).sum(); }, debar_);
    tet_f_.resize(4 * T);
#pragma omp parallel for schedule(static) if (T > 20000)
    for (int64_t t = 0; t < T; ++t) {
      const ElementState& s = state_[t];
      const int32_t g = groups_->group_of_tet[t];
      const Mat3 dP = deviatoric_dpiola(s, dF_[t], tets_.material[t]) +
                      tets_.kappa[t] * (debar_[g] * dilatation_gradient(s) + ebar_[g] * dilatation_dgradient(s, dF_[t]));
      const auto fe = nodal_forces(dP, tets_.rest[t]);   // −V₀ δP D_m⁻ᵀ: the forces' change, −K p
      for (int i = 0; i < 4; ++i) tet_f_[4 * t + i] = -fe[i];
    }
    kp.resize(N);
#pragma omp parallel for schedule(static) if (N > 20000)
    for (int64_t n = 0; n < N; ++n) kp[n] = gather(adj_.tets, n, tet_f_);
  }

  void stiffness_diagonal(std::vector<Mat3>& blocks) override {
    // K_ii per tetrahedron from unit moves of vertex i along each axis, with the tetrahedron's own
    // dilatation (the cube coupling left out: this is only the preconditioner).
    // The blocks of a chunk of tetrahedra on every thread, then summed into the nodes in tetrahedron
    // order on one: the same additions in the same order as a plain loop, so the same numbers.
    at_linearization();
    blocks.assign(m_.node_count(), Mat3::Zero());
    const int64_t T = int64_t(m_.tets.size());
    constexpr int64_t kChunk = 1 << 16;
    std::vector<std::array<Mat3, 4>> chunk(std::size_t(std::min(T, kChunk)));
    for (int64_t first = 0; first < T; first += kChunk) {
      const int64_t n = std::min(kChunk, T - first);
#pragma omp parallel for schedule(static) if (n > 20000)
      for (int64_t c = 0; c < n; ++c) {
        const int64_t t = first + c;
        // ∂F/∂x_i along axis a is e_a ⊗ ∇N_i.
        const std::array<Vec3, 4> grads = shape_gradients(tets_.rest[t]);
        for (int i = 0; i < 4; ++i)
          for (int a = 0; a < 3; ++a) {
            const Mat3 dF = Vec3::Unit(a) * grads[i].transpose();
            chunk[std::size_t(c)][i].col(a) = tets_.rest[t].volume_m3 * dpiola(state_[t], dF, tets_.material[t]) * grads[i];
          }
      }
      for (int64_t c = 0; c < n; ++c)
        for (int i = 0; i < 4; ++i) blocks[m_.tets[first + c][i]] += chunk[std::size_t(c)][i];
    }
  }

  std::vector<double> fire_masses(const ForceModel&) override {
    // The element stiffness at rest (F = I), each tetrahedron with its own dilatation: the cube's mean
    // dilatation only lowers the volumetric energy (Jensen: ½Λē² ≤ Σ ½κ_t V_t e_t²), so this bounds
    // its stiffness too. Row (i, a) of a tetrahedron: Σ over its vertices j and axes b of
    // |V₀ (δP(e_b ⊗ ∇N_j) ∇N_i)_a|.
    const int64_t T = int64_t(m_.tets.size());
    std::vector<std::array<double, 12>> rows(T);
    const ElementState rest = element_state(law_, Mat3::Identity());
#pragma omp parallel for schedule(static) if (T > 20000)
    for (int64_t t = 0; t < T; ++t) {
      const std::array<Vec3, 4> grads = shape_gradients(tets_.rest[t]);
      rows[t].fill(0.0);
      for (int j = 0; j < 4; ++j)
        for (int b = 0; b < 3; ++b) {
          const Mat3 dP = dpiola(rest, Vec3::Unit(b) * grads[j].transpose(), tets_.material[t]);
          for (int i = 0; i < 4; ++i) {
            const Vec3 col = tets_.rest[t].volume_m3 * dP * grads[i];
            for (int a = 0; a < 3; ++a) rows[t][3 * i + a] += std::abs(col[a]);
          }
        }
    }
    std::vector<Vec3> sums(m_.node_count(), Vec3::Zero());
    for (int64_t t = 0; t < T; ++t)
      for (int i = 0; i < 4; ++i) sums[m_.tets[t][i]] += Vec3(rows[t][3 * i], rows[t][3 * i + 1], rows[t][3 * i + 2]);
    std::vector<double> mass(m_.node_count());
    for (int64_t n = 0; n < m_.node_count(); ++n) mass[n] = sums[n].maxCoeff() > 0.0 ? 0.5 * sums[n].maxCoeff() : 1.0;
    return mass;
  }

  int64_t evaluations() const override { return evaluations_; }

 private:
  static Vec3 gather(const Csr& csr, int64_t n, const std::vector<Vec3>& per_vertex) {
    Vec3 sum = Vec3::Zero();
    for (int64_t e = csr.begin(n); e < csr.end(n); ++e) {
      const int32_t it = csr.item[e];
      sum += per_vertex[4 * (it / 8) + it % 8];
    }
    return sum;
  }

  // The element states at x. Newton linearises at the point its line search last evaluated: the
  // states are kept with that point and its model, so the polar decompositions are not done twice.
  void update_states(const ForceModel& model, const std::vector<Vec3>& x) {
    if (!groups_ || groups_->by_cube != model.mean_dilatation) {
      groups_.emplace(m_, tets_, model.mean_dilatation);
      assembly_.reset();
      states_x_.clear();
    }
    if (model.stiffening == states_stiffening_ && x == states_x_) return;
    ++states_version_;
    assembled_current_ = false;
    states_x_ = x;
    states_stiffening_ = model.stiffening;
    const int64_t T = int64_t(m_.tets.size());
    if (fem_law_of(model.material) != law_)
      throw std::logic_error("FemForceField: built for one law, asked for another");
    const FemLaw law = law_;
    state_.resize(T);
#pragma omp parallel for schedule(static) if (T > 20000)
    for (int64_t t = 0; t < T; ++t) {
      const auto& q = m_.tets[t];
      const Mat3 F = edge_matrix(x[q[0]], x[q[1]], x[q[2]], x[q[3]]) * tets_.rest[t].dm_inverse;
      state_[t] = element_state(law, F, model.stiffening);
    }
    // An inverted neo-Hookean element has no dilatation: NaN reaches its forces and the solver.
    group_average([&](int32_t t) { return state_[t].valid ? state_[t].e : NAN; }, ebar_);
  }

  // K is the stiffness at the last linearisation (force_field.h), whatever was evaluated since: a
  // line search between linearize and the products moves the states, which are then put back.
  void at_linearization() {
    if (linear_version_ >= 0 && states_version_ != linear_version_) linearize(linear_model_, std::vector<Vec3>(linear_x_));
  }

  // out[g] = Σ_t w_t q(t) / Λ_g over the tetrahedra of group g (0 for a group without volumetric stiffness).
  template <class PerTet>
  void group_average(PerTet&& q, std::vector<double>& out) const {
    const int64_t G = int64_t(groups_->weight.size());
    out.assign(G, 0.0);
#pragma omp parallel for schedule(static) if (G > 20000)
    for (int64_t g = 0; g < G; ++g) {
      double sum = 0.0;
      for (int32_t i = groups_->begin[g]; i < groups_->begin[g + 1]; ++i) {
        const int32_t t = groups_->tets[i];
        sum += tets_.kappa[t] * tets_.rest[t].volume_m3 * q(t);
      }
      out[g] = groups_->weight[g] > 0.0 ? sum / groups_->weight[g] : 0.0;
    }
  }

  const Mesh& m_;
  FemLaw law_;
  FemStiffness stiffness_;
  Adjacency adj_;
  FemTets tets_;
  std::optional<FemGroups> groups_;   // built for the model's mean_dilatation
  std::optional<FemStiffnessAssembly> assembly_;   // the pattern of groups_, once assembled
  bool assembled_current_ = false;    // assembly_ holds K at states_x_
  std::vector<ElementState> state_;
  std::vector<double> ebar_, debar_;
  std::vector<Mat3> dF_;
  std::vector<Vec3> tet_f_, load_f_;
  std::vector<Vec3> states_x_;        // the positions state_ and ebar_ belong to
  double states_stiffening_ = NAN;
  int64_t states_version_ = 0;        // counts the states computed
  std::vector<Vec3> linear_x_;        // the last linearisation's point, model and states' version
  ForceModel linear_model_;
  int64_t linear_version_ = -1;
  int64_t evaluations_ = 0;
};

}  // namespace

std::unique_ptr<ForceField> make_fem_force_field(const Mesh& m, MaterialModel model, FemStiffness stiffness) {
  return std::make_unique<FemForceField>(m, fem_law_of(model), stiffness);
}

}  // namespace pneumo
