#pragma once
// Forces on the mesh nodes (method.md §5), the plain C++ reference in double precision.
// Positions in metres, velocities in m/s, forces in newtons, pressure in pascal.
#include <cmath>
#include <vector>

#include "mesh/adjacency.h"
#include "mesh/mesh.h"

namespace pneumo {

struct ForceModel {
  MaterialModel material = MaterialModel::Msd;   // springs, or the finite elements of fem_element.h
  bool mean_dilatation = true;                   // FEM: the volumetric strain averaged per cube (fem_force_field.h)
  SpringModel spring_model = SpringModel::Nonlinear;
  bool damping = true;                 // spring dampers c (§4)
  double pressure_pa = 0.0;            // gas pressure on the cavity faces (mesh.h)
  double volume_stiffness_pa = 0.0;    // Kitasaka's k_v; 0 = off
  Vec3 gravity_m_s2 = Vec3::Zero();    // option (Bano); zero = off
  double contact_stiffness = 0.0;      // κ of the viscera's contact with wall and bone (contact.h); 0 = off
  bool tie_interface = false;          // wall bonded to viscera where they touch at rest (interface_tie.h)
  bool tie_attached = false;           // ... only at the attached interfaces (Mesh::node_attached)
  double stiffening = 0.0;             // b of the exponential spring law (stiffened_strain), or of
                                       // Demiray's law for fem-neohookean; 0 = linear / neo-Hookean
};

/// The strain-stiffening spring law (material.stiffening, docs/fidelity.md): a nonlinear spring's
/// tension is k·l₀·g(ε) with ε = (|d| − l₀)/l₀ and g(ε) = (e^{bε} − 1)/b in tension (Fung's exponential,
/// the small-strain stiffness k kept: g'(0) = 1), g(ε) = ε in compression and for b = 0. Its energy is
/// k·l₀²·G(ε), G = (e^{bε} − 1 − bε)/b² in tension, ε²/2 otherwise.
inline double stiffened_strain(double eps, double b) { return b > 0.0 && eps > 0.0 ? std::expm1(b * eps) / b : eps; }
inline double stiffened_energy_density(double eps, double b) {
  return b > 0.0 && eps > 0.0 ? (std::expm1(b * eps) - b * eps) / (b * b) : 0.5 * eps * eps;
}

/// Evaluates every force term for positions x and velocities v (v may be empty: no damping).
/// The result has one entry per node; held axes are not zeroed here (the integrators do that).
/// Gathered per node through `adj`, so it is deterministic and parallel.
class ForceEvaluator {
 public:
  explicit ForceEvaluator(const Mesh& mesh);
  void evaluate(const ForceModel& model, const std::vector<Vec3>& x, const std::vector<Vec3>& v,
                std::vector<Vec3>& f);
  const Adjacency& adjacency() const { return adj_; }
  int64_t evaluations() const { return evaluations_; }

 private:
  const Mesh& m_;
  Adjacency adj_;
  std::vector<Vec3> spring_f_, tet_f_, load_f_;   // per element, before the gather
  int64_t evaluations_ = 0;
};

/// Nonlinear spring and damper force on node a of spring (a,b): f_a = −k(|d|−|d₀|)d̂ − c(v_ab·d̂)d̂ (§5).
/// With stiffening b > 0 the elastic part is −k·l₀·g(ε)·d̂ (stiffened_strain).
Vec3 spring_force_nonlinear(const Vec3& xa, const Vec3& xb, const Vec3& va, const Vec3& vb, double rest, double k,
                            double c, double stiffening = 0.0);
/// Nimura's Eq. 1 as printed (option): f_a = −k(d − d₀) − c v_ab. Not rotation-invariant.
Vec3 spring_force_linear(const Vec3& xa, const Vec3& xb, const Vec3& xa0, const Vec3& xb0, const Vec3& va,
                         const Vec3& vb, double k, double c);
/// ∂V/∂x_i of a tetrahedron's signed volume, for its 4 vertices.
std::array<Vec3, 4> tet_volume_gradient(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d);

/// Potential energies (J), for invariants and tests.
double spring_energy(const Mesh& m, const std::vector<Vec3>& x, SpringModel model, double stiffening = 0.0);
double volume_energy(const Mesh& m, const std::vector<Vec3>& x, double volume_stiffness_pa);
double kinetic_energy(const Mesh& m, const std::vector<Vec3>& v);
/// Tetrahedra whose signed volume is ≤ 0.
int64_t count_inverted(const Mesh& m, const std::vector<Vec3>& x);

}  // namespace pneumo
