#pragma once
// A mesh's piecewise-linear node field read at arbitrary points of its rest frame, for comparing a
// solution with a closed form where the closed form lives (Lamé's true spheres, lame_sphere.cpp),
// not at the nodes, which a cube lattice places up to a cube away.
#include <array>
#include <cstdint>
#include <unordered_map>
#include <vector>

#include "mesh/mesh.h"

namespace pneumo {

class TetField {
 public:
  /// `m` (a cube lattice of cube_m metres, mesh.h) must outlive the field.
  TetField(const Mesh& m, double cube_m);

  /// The field of the node values `u` at rest point p (metres): carried by the tetrahedron of p's
  /// lattice cube that holds it (the largest smallest barycentric weight); where no meshed cube holds p
  /// (a staircase inside a curved surface), by the tetrahedron of a neighbouring cube whose weights are
  /// least negative, a linear extrapolation over at most a cube, and `outside` is set. Throws
  /// std::logic_error when no neighbouring cube is meshed either.
  Vec3 at(const Vec3& p, const std::vector<Vec3>& u, bool& outside) const;

 private:
  std::array<int64_t, 3> cell(const Vec3& p) const;
  std::array<double, 4> weights(int32_t t, const Vec3& p) const;
  const Mesh& m_;
  double cube_m_;
  Vec3 origin_;
  std::unordered_map<int64_t, std::vector<int32_t>> by_cube_;   // lattice cube → its tetrahedra
};

/// n points spread evenly over the unit sphere (the Fibonacci lattice), each standing for 1/n of its area.
std::vector<Vec3> fibonacci_sphere(int n);

}  // namespace pneumo
