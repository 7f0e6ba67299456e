#pragma once
// The cube lattice's combinatorics (method.md §3; Kitasaka §2.3, Nimura §2.2): which cube corners
// form the 5 tetrahedra of a cube, and how a cube face splits into 2 triangles, for both mirror
// patterns. Pure data and functions, no mesh.
//
// Corner c of a cube has offset (c & 1, (c >> 1) & 1, (c >> 2) & 1). A cube (a,b,c) uses the "even"
// pattern when a+b+c is even: its central tetrahedron joins the corners of odd offset-sum, so every
// face diagonal joins two lattice nodes whose (i+j+k) is odd. The "odd" pattern mirrors it, and its
// diagonals join globally odd nodes too: neighbouring cubes' diagonals coincide on shared faces.
#include <array>
#include <cstdint>

namespace pneumo::lattice {

using Tet = std::array<int, 4>;       // corner indices 0..7
using Tri = std::array<int, 3>;

inline constexpr std::array<int, 3> corner_offset(int corner) {
  return {corner & 1, (corner >> 1) & 1, (corner >> 2) & 1};
}

/// The 5 tetrahedra of a cube: the central one first, then the 4 corner ones. Orientation is not
/// guaranteed: the mesh orients each by its rest volume (a flipped world axis flips signs).
inline constexpr std::array<Tet, 5> cube_tets(bool odd_cube) {
  if (!odd_cube) return {{{1, 2, 4, 7}, {0, 1, 2, 4}, {3, 1, 2, 7}, {5, 1, 4, 7}, {6, 2, 4, 7}}};
  return {{{0, 3, 5, 6}, {1, 0, 3, 5}, {2, 0, 3, 6}, {4, 0, 5, 6}, {7, 3, 5, 6}}};
}

/// Which of cube_tets(odd_cube) holds the point u of the unit cube (local coordinates in [0,1]³):
/// corner tetrahedron k (1..4) is the set Σ_a |u_a − o_a| ≤ 1 around its corner o, the central one
/// (0) the rest. Points on a shared face go to the corner tetrahedron.
inline int tet_holding(const std::array<double, 3>& u, bool odd_cube) {
  const auto tets = cube_tets(odd_cube);
  for (int k = 1; k < 5; ++k) {
    const auto o = corner_offset(tets[k][0]);
    double d = 0.0;
    for (int a = 0; a < 3; ++a) d += o[a] ? 1.0 - u[a] : u[a];
    if (d <= 1.0) return k;
  }
  return 0;
}

/// The 6 faces of a cube: axis (0,1,2), side (0 = low, 1 = high) and its 4 corners in cyclic order.
struct Face {
  int axis, side;
  std::array<int, 4> corners;   // cyclic around the face
};
std::array<Face, 6> cube_faces();

/// The two triangles of a face, split along the diagonal the cube's pattern uses. Orientation is not
/// guaranteed (the mesh orients them out of their solid by geometry).
std::array<Tri, 2> face_triangles(const Face& face, bool odd_cube);

}  // namespace pneumo::lattice
