#pragma once
// What every implementation of the finite elements derives from the mesh once: each tetrahedron's
// rest data, Lamé parameters and volumetric modulus, and the groups of the mean dilatation
// (fem_force_field.cpp explains the averaging). The CPU reference and the OpenCL field share it,
// so both average over the same groups in the same order.
#include <cstdint>
#include <vector>

#include "mesh/mesh.h"
#include "solve/fem_element.h"

namespace pneumo {

struct FemTets {
  FemLaw law = FemLaw::Corotational;
  std::vector<TetRest> rest;
  std::vector<TetMaterial> material;   // μ, λ and the fibre family (fem_element.h)
  std::vector<double> kappa;   // the law's volumetric modulus (fem_element.h)
  FemTets(const Mesh& m, FemLaw law);
};

/// The tetrahedra of one cube and part (mean_dilatation), or each alone: group g holds
/// tets[begin[g]] … tets[begin[g + 1] − 1]; weight[g] = Σ κ_t V_t over them.
struct FemGroups {
  std::vector<int32_t> group_of_tet, tets, begin;
  std::vector<double> weight;
  bool by_cube = false;
  FemGroups(const Mesh& m, const FemTets& t, bool mean_dilatation);
};

FemLaw fem_law_of(MaterialModel m);

}  // namespace pneumo
