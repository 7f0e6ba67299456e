#pragma once
// Voxels per mesh cube edge along each grid axis (i, j, k): the lattice of method.md §3 on any grid.
// A cube of L_a voxels on axis a spans index coordinates [n·L_a − ½, (n+1)·L_a − ½), so on a grid
// of 0.7 × 0.7 × 2.5 mm voxels L = (13, 13, 4) gives cubes of 9.1 × 9.1 × 10 mm, where one L for all
// axes gave 9.1 × 9.1 × 32.5 or 2.8 × 2.8 × 10 mm. One integer converts implicitly (the same on every
// axis): on an isotropic lattice everything is as it was with one L.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <ostream>
#include <string>

#include "core/geometry.h"

namespace pneumo {

struct CubeVoxels {
  std::array<int, 3> n{8, 8, 8};

  constexpr CubeVoxels() = default;
  constexpr CubeVoxels(int all) : n{all, all, all} {}   // NOLINT: one L on every axis, as before
  constexpr CubeVoxels(int i, int j, int k) : n{i, j, k} {}

  constexpr int operator[](int axis) const { return n[std::size_t(axis)]; }
  constexpr int& operator[](int axis) { return n[std::size_t(axis)]; }
  constexpr bool operator==(const CubeVoxels& o) const { return n[0] == o.n[0] && n[1] == o.n[1] && n[2] == o.n[2]; }
  constexpr bool operator!=(const CubeVoxels& o) const { return !(*this == o); }

  constexpr bool uniform() const { return n[0] == n[1] && n[1] == n[2]; }
  constexpr int min() const { return std::min({n[0], n[1], n[2]}); }
  constexpr int max() const { return std::max({n[0], n[1], n[2]}); }
  /// Voxels per cube.
  constexpr int64_t volume() const { return int64_t(n[0]) * n[1] * n[2]; }
  /// Every axis at least 1.
  constexpr bool valid() const { return min() >= 1; }
  /// The cube index holding voxel index i on `axis` (i ≥ 0).
  constexpr int64_t cube_of(int axis, int64_t i) const { return i / n[std::size_t(axis)]; }
  /// Cubes needed to cover `dims` voxels, per axis.
  std::array<int64_t, 3> cubes_for(const Index3& dims) const {
    std::array<int64_t, 3> c{};
    for (int a = 0; a < 3; ++a) c[std::size_t(a)] = (dims[a] + n[std::size_t(a)] - 1) / n[std::size_t(a)];
    return c;
  }
  /// The cube's edge on each axis in mm on a grid of `spacing_mm`.
  Vec3 edge_mm(const Vec3& spacing_mm) const {
    return Vec3(n[0] * spacing_mm[0], n[1] * spacing_mm[1], n[2] * spacing_mm[2]);
  }
  /// "8" when uniform, else "13×13×4": how messages and logs name it.
  std::string text() const {
    if (uniform()) return std::to_string(n[0]);
    return std::to_string(n[0]) + "×" + std::to_string(n[1]) + "×" + std::to_string(n[2]);
  }
};

inline std::ostream& operator<<(std::ostream& os, const CubeVoxels& c) { return os << c.text(); }

/// Per axis the whole number of voxels nearest to `cube_mm`, at least 1: near-isotropic cubes of about cube_mm
/// on any grid (within half a voxel per axis).
inline CubeVoxels cube_voxels_for_mm(double cube_mm, const Vec3& spacing_mm) {
  CubeVoxels c;
  for (int a = 0; a < 3; ++a) c[a] = std::max(1, int(std::lround(cube_mm / spacing_mm[a])));
  return c;
}

}  // namespace pneumo
