#include "solve/forces.h"

#include <cmath>

namespace pneumo {

Vec3 spring_force_nonlinear(const Vec3& xa, const Vec3& xb, const Vec3& va, const Vec3& vb, double rest, double k,
                            double c, double stiffening) {
  const Vec3 d = xa - xb;
  const double len = d.norm();
  if (!(len > 0.0)) return Vec3::Zero();   // coincident nodes: no direction
  const Vec3 dir = d / len;
  const double stretch = stiffening > 0.0 && rest > 0.0 ? rest * stiffened_strain((len - rest) / rest, stiffening)
                                                         : len - rest;
  return -k * stretch * dir - c * (va - vb).dot(dir) * dir;
}

Vec3 spring_force_linear(const Vec3& xa, const Vec3& xb, const Vec3& xa0, const Vec3& xb0, const Vec3& va,
                         const Vec3& vb, double k, double c) {
  return -k * ((xa - xb) - (xa0 - xb0)) - c * (va - vb);
}

std::array<Vec3, 4> tet_volume_gradient(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
  // V = (b−a)·((c−a)×(d−a))/6, written cyclically for c and d; ∂V/∂a follows from translation
  // invariance (the four gradients sum to zero).
  std::array<Vec3, 4> g;
  g[1] = (c - a).cross(d - a) / 6.0;
  g[2] = (d - a).cross(b - a) / 6.0;
  g[3] = (b - a).cross(c - a) / 6.0;
  g[0] = -(g[1] + g[2] + g[3]);
  return g;
}

ForceEvaluator::ForceEvaluator(const Mesh& mesh) : m_(mesh), adj_(Adjacency::of(mesh)) {}

void ForceEvaluator::evaluate(const ForceModel& model, const std::vector<Vec3>& x, const std::vector<Vec3>& v,
                              std::vector<Vec3>& f) {
  const Mesh& m = m_;
  const int64_t S = int64_t(m.springs.size()), T = int64_t(m.tets.size()), R = int64_t(m.load_tet.size());
  const int64_t N = m.node_count();
  const bool damp = model.damping && !v.empty();
  static const Vec3 kZero = Vec3::Zero();
  spring_f_.resize(S);
  tet_f_.resize(model.volume_stiffness_pa != 0.0 ? 4 * T : 0);
  load_f_.resize(model.pressure_pa != 0.0 ? 4 * R : 0);
  f.resize(N);

  // Small meshes stay on one thread: a parallel region costs more than their whole evaluation.
#pragma omp parallel if (N + S > 20000)
  {
    // Per element: the force on its first node (springs) or on each vertex (tetrahedra).
#pragma omp for schedule(static)
    for (int64_t s = 0; s < S; ++s) {
      const int32_t a = m.springs[s][0], b = m.springs[s][1];
      const double c = damp ? m.spring_c[s] : 0.0;
      const Vec3& va = damp ? v[a] : kZero;
      const Vec3& vb = damp ? v[b] : kZero;
      spring_f_[s] = model.spring_model == SpringModel::Nonlinear
                         ? spring_force_nonlinear(x[a], x[b], va, vb, m.spring_rest_m[s], m.spring_k[s], c,
                                                  model.stiffening)
                         : spring_force_linear(x[a], x[b], m.rest_m[a], m.rest_m[b], va, vb, m.spring_k[s], c);
    }
    if (!tet_f_.empty()) {
      // Kitasaka's F_v: U = ½ k_v V₀ ((V − V₀)/V₀)², f_i = −k_v ((V − V₀)/V₀) ∂V/∂x_i (§5).
#pragma omp for schedule(static)
      for (int64_t t = 0; t < T; ++t) {
        const auto& q = m.tets[t];
        const double v0 = m.tet_rest_volume_m3[t];
        const double vol = signed_tet_volume(x[q[0]], x[q[1]], x[q[2]], x[q[3]]);
        const auto g = tet_volume_gradient(x[q[0]], x[q[1]], x[q[2]], x[q[3]]);
        // k_v is a material property: the tissue that fills the tetrahedron carries it (mesh.h).
        const double s = -model.volume_stiffness_pa * m.tet_fraction[t] * (vol - v0) / v0;
        for (int i = 0; i < 4; ++i) tet_f_[4 * t + i] = s * g[i];
      }
    }
    if (!load_f_.empty()) {
#pragma omp for schedule(static)
      for (int64_t r = 0; r < R; ++r) {
        const auto fl = pressure_load_forces(m, r, x, model.pressure_pa);
        for (int i = 0; i < 4; ++i) load_f_[4 * r + i] = fl[i];
      }
    }
    // Gather per node, in a fixed order: the same sum whatever the thread count.
#pragma omp for schedule(static)
    for (int64_t n = 0; n < N; ++n) {
      Vec3 sum = model.gravity_m_s2 * (m.mass_kg.empty() ? 0.0 : m.mass_kg[n]);
      for (int64_t e = adj_.springs.begin(n); e < adj_.springs.end(n); ++e) {
        const int32_t it = adj_.springs.item[e];
        sum += (it % 8 == 0) ? spring_f_[it / 8] : Vec3(-spring_f_[it / 8]);
      }
      if (!tet_f_.empty())
        for (int64_t e = adj_.tets.begin(n); e < adj_.tets.end(n); ++e) {
          const int32_t it = adj_.tets.item[e];
          sum += tet_f_[4 * (it / 8) + it % 8];
        }
      if (!load_f_.empty())
        for (int64_t e = adj_.loads.begin(n); e < adj_.loads.end(n); ++e) {
          const int32_t it = adj_.loads.item[e];
          sum += load_f_[4 * (it / 8) + it % 8];
        }
      f[n] = sum;
    }
  }
  ++evaluations_;
}

double spring_energy(const Mesh& m, const std::vector<Vec3>& x, SpringModel model, double stiffening) {
  double e = 0.0;
  for (std::size_t s = 0; s < m.springs.size(); ++s) {
    const int32_t a = m.springs[s][0], b = m.springs[s][1];
    if (model == SpringModel::Nonlinear) {
      const double l0 = m.spring_rest_m[s];
      const double eps = ((x[a] - x[b]).norm() - l0) / l0;
      e += m.spring_k[s] * l0 * l0 * stiffened_energy_density(eps, stiffening);
    } else {
      e += 0.5 * m.spring_k[s] * ((x[a] - x[b]) - (m.rest_m[a] - m.rest_m[b])).squaredNorm();
    }
  }
  return e;
}

double volume_energy(const Mesh& m, const std::vector<Vec3>& x, double kv) {
  double e = 0.0;
  for (std::size_t t = 0; t < m.tets.size(); ++t) {
    const auto& q = m.tets[t];
    const double v0 = m.tet_rest_volume_m3[t];
    const double strain = (signed_tet_volume(x[q[0]], x[q[1]], x[q[2]], x[q[3]]) - v0) / v0;
    e += 0.5 * kv * m.tet_fraction[t] * v0 * strain * strain;
  }
  return e;
}

double kinetic_energy(const Mesh& m, const std::vector<Vec3>& v) {
  double e = 0.0;
  for (int64_t n = 0; n < m.node_count(); ++n) e += 0.5 * m.mass_kg[n] * v[n].squaredNorm();
  return e;
}

int64_t count_inverted(const Mesh& m, const std::vector<Vec3>& x) {
  int64_t n = 0;
#pragma omp parallel for reduction(+ : n) schedule(static)
  for (int64_t t = 0; t < int64_t(m.tets.size()); ++t) {
    const auto& q = m.tets[t];
    n += signed_tet_volume(x[q[0]], x[q[1]], x[q[2]], x[q[3]]) <= 0.0;
  }
  return n;
}

}  // namespace pneumo
