#include "mesh/cube_lattice.h"

namespace pneumo::lattice {

std::array<Face, 6> cube_faces() {
  std::array<Face, 6> faces{};
  int n = 0;
  for (int axis = 0; axis < 3; ++axis) {
    const int u = (axis + 1) % 3, v = (axis + 2) % 3;
    for (int side = 0; side < 2; ++side) {
      Face f{axis, side, {}};
      // Walk (u,v) = (0,0) (1,0) (1,1) (0,1): cyclic around the face.
      const int uv[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
      for (int q = 0; q < 4; ++q) {
        int bits[3];
        bits[axis] = side;
        bits[u] = uv[q][0];
        bits[v] = uv[q][1];
        f.corners[q] = bits[0] | (bits[1] << 1) | (bits[2] << 2);
      }
      faces[n++] = f;
    }
  }
  return faces;
}

std::array<Tri, 2> face_triangles(const Face& face, bool odd_cube) {
  // The diagonal joins the two corners whose offset-sum parity is odd in an even cube, even in an
  // odd cube (see the header). In cyclic order those are positions (0,2) or (1,3).
  auto parity = [](int c) { auto o = corner_offset(c); return (o[0] + o[1] + o[2]) & 1; };
  const int want = odd_cube ? 0 : 1;
  const auto& c = face.corners;
  if (parity(c[0]) == want)   // diagonal c0–c2
    return {{{c[0], c[1], c[2]}, {c[0], c[2], c[3]}}};
  return {{{c[1], c[2], c[3]}, {c[1], c[3], c[0]}}};   // diagonal c1–c3
}

}  // namespace pneumo::lattice
