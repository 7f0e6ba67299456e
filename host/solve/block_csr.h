#pragma once
// A sparse matrix of 3×3 blocks in compressed rows, one block row and column per node: for a
// stiffness that is assembled once per linearisation and then multiplied many times (Newton's CG
// takes tens of products per step; fem_stiffness_assembly.h).
//
// The pattern comes from groups of nodes: every ordered pair of nodes that share a group has a block
// (for the finite elements a group is a cube's tetrahedra, whose mean dilatation couples all its
// nodes, or one tetrahedron).
#include <cstdint>
#include <vector>

#include "core/geometry.h"

namespace pneumo {

struct BlockCsr {
  std::vector<int64_t> row_start;   // rows + 1
  std::vector<int32_t> col;         // ascending within each row
  std::vector<Mat3> block;          // one per entry of col

  int64_t rows() const { return int64_t(row_start.size()) - 1; }
  /// The index of block (row, column) in col/block, or −1 where the pattern has none.
  int64_t find(int32_t row, int32_t column) const;
  /// y = A x (y resized to rows()).
  void multiply(const std::vector<Vec3>& x, std::vector<Vec3>& y) const;
};

/// The pattern (blocks zero) of all pairs of nodes within a group: group g holds the nodes
/// nodes[begin[g]] … nodes[begin[g + 1] − 1], each once.
BlockCsr block_pattern_of_groups(int64_t node_count, const std::vector<int64_t>& begin,
                                 const std::vector<int32_t>& nodes);

}  // namespace pneumo
