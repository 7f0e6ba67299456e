#pragma once
// The wall bonded to the viscera where they touch at rest, for the one state in which no gas
// separates them: the CT itself, carrying its weight (gravity_compensation.h). The wall and the
// viscera are separate meshes, doubled where they touch (mesh.h), so without a bond gravity lets the
// wall fall through the viscera it lies on (on the real CT, 36 mm and −644 ml of "cavity" under
// gravity alone) and the unloaded shape would be lifted by that fall.
//
// Each wall node and the viscera node at the same lattice point form a pair, held by a linear spring
// of zero length relative to their rest offset: energy ½ k |(x_w − x_v) − (X_w − X_v)|². k is κ = 10
// times the stiffer node's own spring stiffness (Σ over its tetrahedra of Lloyd's k for their modulus
// and volume, mesh.h), so the pair slips by a tenth of what the tissue next to it deforms under the
// same force.
//
// The same bond holds for good where the viscera lie on an organ the scene lists as attached
// (MeshOptions::attached_labels): there the gas does not open, so the gas in front pushes the
// viscera back against it, as the bowel moves dorsally in patients, instead of floating them in gas.
#include <memory>
#include <vector>

#include "mesh/mesh.h"

namespace pneumo {

class ForceField;
struct ForceModel;

struct TiedPair {
  int32_t wall = 0, viscera = 0;
  double stiffness_n_per_m = 0;
};

/// The coincident wall/viscera node pairs of m and their bond stiffness; with `attached_only`, the
/// pairs whose nodes are both marked in m.node_attached.
std::vector<TiedPair> interface_pairs(const Mesh& m, bool attached_only = false);

/// `inner` with the bond added when model.tie_interface is set (every pair) or model.tie_attached
/// (the attached interfaces' pairs: retroperitoneal organs the viscera stay on, MeshOptions) and m
/// has such pairs; `inner` otherwise.
std::unique_ptr<ForceField> with_interface_tie(const Mesh& m, const ForceModel& model, std::unique_ptr<ForceField> inner);

}  // namespace pneumo
