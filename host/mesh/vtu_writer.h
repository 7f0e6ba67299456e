#pragma once
// VTK XML unstructured grids (.vtu) of the mesh, for ParaView: tetrahedra with per-point displacement
// (mm), role (0 wall, 1 viscera), fixed flag, and per-cell part and label. Written atomically.
#include <string>
#include <vector>

#include "mesh/mesh.h"

namespace pneumo {

/// Writes the mesh at positions x (metres; the rest positions when empty), in millimetres.
void write_vtu(const Mesh& m, const std::vector<Vec3>& x, const std::string& path);

}  // namespace pneumo
