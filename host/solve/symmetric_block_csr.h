#pragma once
// A symmetric sparse matrix of 3×3 blocks, one block row and column per node, stored as its upper
// triangle (blocks (r, c) with c ≥ r) in compressed rows: for a stiffness that is assembled once per
// linearisation and then multiplied many times (Newton's CG takes tens of products per step;
// fem_stiffness_assembly.h). The product is bound by reading the blocks, so storing half of them
// halves its time.
//
// The pattern comes from groups of nodes: every pair of nodes that share a group has a block (for the
// finite elements a group is a cube's tetrahedra, whose mean dilatation couples all its nodes, or
// one tetrahedron).
#include <cstdint>
#include <vector>

#include "core/geometry.h"

namespace pneumo {

struct SymmetricBlockCsr {
  std::vector<int64_t> row_start;   // rows + 1
  std::vector<int32_t> col;         // ascending within each row, each ≥ the row
  std::vector<Mat3> block;          // one per entry of col; block (c, r) is this one transposed

  int64_t rows() const { return int64_t(row_start.size()) - 1; }
  /// The index of block (row, column), column ≥ row, in col/block, or −1 where the pattern has none.
  int64_t find(int32_t row, int32_t column) const;
  /// y = A x (y resized to rows()), the lower triangle as the upper one's transpose. Bit for bit the
  /// same at any thread count: the sums run in an order fixed by the matrix alone.
  void multiply(const std::vector<Vec3>& x, std::vector<Vec3>& y) const;

 private:
  static constexpr int64_t kMaxChunks = 64;
  /// The rows cut into chunks (first[c] … first[c + 1] − 1), each with the partial sums of its
  /// transposed blocks over rows first[c] … reach[c] − 1, at partial[offset[c]…]; lowest[k] is the
  /// first chunk whose partial sums reach into chunk k. Made at the first product after the pattern
  /// changes.
  struct ChunkPlan {
    int64_t rows = -1, entries = -1;
    std::vector<int64_t> first, reach, offset, lowest;
    std::vector<Vec3> partial;
  };
  void plan_chunks() const;
  mutable ChunkPlan plan_;
};

/// The pattern (blocks zero) of all pairs of nodes within a group: group g holds the nodes
/// nodes[begin[g]] … nodes[begin[g + 1] − 1], each once.
SymmetricBlockCsr symmetric_pattern_of_groups(int64_t node_count, const std::vector<int64_t>& begin,
                                              const std::vector<int32_t>& nodes);

}  // namespace pneumo
