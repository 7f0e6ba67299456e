#pragma once
// Frictionless penalty contact (docs/contact.md): the viscera must not pass through the
// wall or through bone when gravity, a tilt or a low pressure pushes them together.
//
// The surfaces are the voxel faces of mesh.h's ContactFaces: each viscera face (the slave) is a point
// p_s = Σ w_i x_i embedded in its tetrahedron, with the deformed normal n_s = cof(D_s)·c / |·|. Its
// partner (the master) is the nearest wall face whose normal opposes it (n_s·n_m < −½) or the nearest
// bone face, found in a spatial hash of the masters' deformed centres (Teschner et al. 2003) at every
// force evaluation, so the viscera slide along the wall instead of being tied to the face they started
// on. With the gap g = (p_s − p_m)·n_m along the master's outward normal, a pair is in contact when
// g < 0 and the slave lies over the master face (its offset along the face within ¾ of the face's
// size) and no deeper than one cube: then the energy ½ k A g² pushes the slave out along n_m and the
// master back (Newton's third law; no tangential force: frictionless). At rest every viscera face
// coincides with its wall face, g = 0, and nothing acts; the gas opening the cavity only widens gaps.
//
// The penalty per unit area and depth is k = κ·E/h, with E the stiffer of the two tissues' own moduli
// (a tetrahedron's modulus divided by its tissue share), h the cube edge and κ the scene's
// material.contact_stiffness: a cube face of contact is then κ times as stiff as a tetrahedron behind
// it, and the penetration at a contact pressure p_c is p_c·h/(κE) (κ = 10, E = 5 kPa: 0.2 mm under the
// viscera's own weight on a 9 mm mesh). With the softer side's modulus instead, the stiff wall pressing
// soft fat drove faces deeper than a cube on the real CT and Newton found no descent. One pass (viscera against wall and bone), as node-to-surface contact
// usually is: a wall face may still dip between viscera sample points, by less than a voxel.
//
// Within an evaluation the pairs and their normals are frozen: the forces are −∇ of the energy at
// frozen normals, and the stiffness K = k A (Σw_s − Σw_m)ᵀ ⊗ n nᵀ is their exact derivative (the
// rotation of n, of the order of the gap, is left out, as penalty contact usually does; SOFA's
// penalty contact does the same). Touching pairs (0 ≤ g < 10⁻⁶ h: at rest, every one) carry no force
// but their stiffness: the energy's kink at g = 0 is taken from the pressed side, as a semi-smooth
// Newton method takes it. Without it a Newton step from rest would push the viscera through the
// wall, and no step along it would lower the residual; with it a step from rest presses as far as the
// penalty allows and, where the gas pulls the surfaces apart, opens them by p/k, after which those
// pairs leave the stiffness.
#include <cstdint>
#include <memory>
#include <vector>

#include "mesh/mesh.h"

namespace pneumo {

class ForceField;
struct ForceModel;

/// One contact: slave face s (a viscera ContactFaces index) against master face m (a wall
/// ContactFaces index, or fixed face −1 − m when m < 0), with the master's unit normal n, the gap g
/// (m; < 0 pressed, ≥ 0 touching) and k A (N/m).
struct ContactPair {
  int32_t slave = 0, master = 0;
  Vec3 normal = Vec3::Zero();
  double gap_m = 0.0;
  double stiffness_n_per_m = 0.0;
};

/// Finds the faces in contact at positions x with penalty κ (contact.h's rule).
class ContactSearch {
 public:
  ContactSearch(const Mesh& m, double kappa);
  std::vector<ContactPair> find(const std::vector<Vec3>& x) const;
  /// k A of a slave face against a master of modulus E_m (0 for bone), N/m: κ max(E_s, E_m) A_s / h.
  double pair_stiffness(int32_t slave, double master_young_pa) const;
  /// Per ContactFaces index: the stiffest pair (k A) the face may form with the other side's faces
  /// within a cube of it at rest, what bounds FIRE's masses.
  std::vector<double> stiffness_bounds() const;
  const std::vector<int32_t>& slaves() const { return slaves_; }

 private:
  const Mesh& m_;
  double kappa_, cell_m_ = 0, depth_limit_m_ = 0, cube_edge_m_ = 0, touch_m_ = 0;
  std::vector<int32_t> slaves_, masters_;   // ContactFaces indices
  std::vector<double> rest_area_m2_;        // per ContactFaces index
  std::vector<double> tissue_young_pa_;     // per ContactFaces index: its tissue's own modulus
};

/// Σ w v over the slave's vertices minus the same over the master's (none for bone): the pair's
/// relative motion for nodal motions v.
Vec3 relative_motion(const Mesh& m, const ContactPair& p, const std::vector<Vec3>& v);
/// Slave point minus master point, both at x (the master's: fixed centre when m < 0).
Vec3 contact_offset(const Mesh& m, const ContactPair& p, const std::vector<Vec3>& x);
/// Adds the pairs' forces at x to f (−k A g n on the slave's vertices by their weights, the opposite on
/// the master's), with the frozen normals.
void add_contact_forces(const Mesh& m, const std::vector<ContactPair>& pairs, const std::vector<Vec3>& x,
                        std::vector<Vec3>& f);
/// ½ Σ k A g² over the pairs with g = offset · n < 0 at x (frozen normals), J.
double contact_energy(const Mesh& m, const std::vector<ContactPair>& pairs, const std::vector<Vec3>& x);

/// `inner` with the contact term added when model.contact_stiffness > 0; `inner` itself otherwise.
std::unique_ptr<ForceField> with_contact(const Mesh& m, const ForceModel& model, std::unique_ptr<ForceField> inner);

}  // namespace pneumo
