#pragma once
// One interface for every material model's forces on the mesh:
// the springs of method.md §5 (spring_force_field.cpp) and the tetrahedral finite elements
// (fem_force_field.cpp) implement it, and the solvers see only this. A new material model is a new
// implementation and one line in make_force_field().
//
// Besides the forces, a model offers its linearisation for the Newton solver: the stiffness
// K = −∂f_elastic/∂x at a state, as a matrix-free product and as the 3×3 blocks of its diagonal
// (the preconditioner). The pressure's follower load is not in K: its stiffness is the same for
// every model (pressure_stiffness.h); gravity, a constant force, has none. Units: metres, newtons,
// joules.
#include <cstdint>
#include <memory>
#include <vector>

#include "mesh/mesh.h"
#include "solve/forces.h"

namespace pneumo {

class NewtonLinearSolver;
struct TiedPair;

class ForceField {
 public:
  virtual ~ForceField() = default;
  /// Every force term of `model` at positions x and velocities v (v may be empty: no damping), one
  /// entry per node; held axes are not zeroed (the solvers do that).
  virtual void evaluate(const ForceModel& model, const std::vector<Vec3>& x, const std::vector<Vec3>& v,
                        std::vector<Vec3>& f) = 0;
  /// The elastic energy at x (J): what the elastic forces are minus the gradient of.
  virtual double elastic_energy(const ForceModel& model, const std::vector<Vec3>& x) = 0;
  /// Prepares stiffness_product and stiffness_diagonal at x.
  virtual void linearize(const ForceModel& model, const std::vector<Vec3>& x) = 0;
  /// kp = K p at the last linearisation.
  virtual void stiffness_product(const std::vector<Vec3>& p, std::vector<Vec3>& kp) = 0;
  /// The 3×3 diagonal blocks K_nn at the last linearisation, one per node.
  virtual void stiffness_diagonal(std::vector<Mat3>& blocks) = 0;
  /// FIRE's fictitious masses (solve_static_fire.cpp): per node a mass m_i with Σ_j |K_ij| ≤ 2 m_i on
  /// each of its three rows of the stiffness at rest (Gershgorin), so every mode has ω² ≤ 2 whatever
  /// the mesh, cube size or moduli. Never zero (a node without stiffness gets 1).
  virtual std::vector<double> fire_masses(const ForceModel& model) = 0;
  /// Force evaluations so far (stiffness products not counted).
  virtual int64_t evaluations() const = 0;
  /// Newton's whole linear solve where this field keeps its state (an OpenCL device: newton_cl.h),
  /// with the pressure's stiffness and the bonds `ties` added to this field's K; nullptr where the
  /// host solves it (newton_linear_solver.h). A field that wraps another adds its own terms or, where
  /// the device cannot hold them (contact), answers nullptr.
  virtual std::unique_ptr<NewtonLinearSolver> device_linear_solver(const std::vector<TiedPair>& ties);
};

/// The force field of `model.material` on mesh m, with the contact term when model.contact_stiffness > 0
/// and the wall-viscera bond when model.tie_interface.
std::unique_ptr<ForceField> make_force_field(const Mesh& m, const ForceModel& model);

/// How the finite elements multiply by their stiffness: assembled once per linearisation
/// (fem_stiffness_assembly.h; the default) or matrix-free, evaluating each element's tangent per
/// product (the reference, which the assembled product is tested against).
enum class FemStiffness : uint8_t { Assembled, MatrixFree };

/// The implementations (what make_force_field picks from).
std::unique_ptr<ForceField> make_spring_force_field(const Mesh& m);
std::unique_ptr<ForceField> make_fem_force_field(const Mesh& m, MaterialModel model,
                                                 FemStiffness stiffness = FemStiffness::Assembled);

}  // namespace pneumo
