#pragma once
// For each node, the springs, tetrahedra and pressure loads it belongs to (compressed rows), so
// forces can be gathered per node: deterministic and parallel without atomics.
#include <cstdint>
#include <vector>

#include "mesh/mesh.h"

namespace pneumo {

struct Csr {
  std::vector<int64_t> start;   // node_count + 1
  std::vector<int32_t> item;    // element index × 8 + local slot (vertex 0..3, or spring end 0..1)
  int64_t begin(int64_t n) const { return start[n]; }
  int64_t end(int64_t n) const { return start[n + 1]; }
};

struct Adjacency {
  Csr springs, tets, loads;   // loads: the pressure loads whose tetrahedron holds the node
  /// Neighbouring nodes through springs, for the sequential 2004 scheme.
  static Adjacency of(const Mesh& m);
};

}  // namespace pneumo
