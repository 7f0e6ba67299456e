#include "warp/cavity_specks.h"

#include <cstdint>
#include <vector>

namespace pneumo {

namespace {

/// One bit per voxel. The gas is a few per cent of a grid of up to 10⁸ voxels: a byte or a piece id
/// per voxel would cost 8 or 32 times the memory, and the fresh pages' faults cost more than the search.
class VoxelBits {
 public:
  explicit VoxelBits(int64_t n) : words_(std::size_t((n + 63) / 64), 0) {}
  bool test(int64_t v) const { return (words_[std::size_t(v >> 6)] >> (v & 63)) & 1u; }
  void set(int64_t v) { words_[std::size_t(v >> 6)] |= uint64_t(1) << (v & 63); }
  void clear(int64_t v) { words_[std::size_t(v >> 6)] &= ~(uint64_t(1) << (v & 63)); }

 private:
  std::vector<uint64_t> words_;
};

}  // namespace

SpeckFill fill_cavity_specks(WarpResult& r, const Index3& dims, int64_t min_voxels) {
  SpeckFill out;
  const int64_t n = dims[0] * dims[1] * dims[2];
  if (min_voxels <= 1 || int64_t(r.outcome.size()) != n) return out;
  const bool labels = int64_t(r.labels.size()) == n;
  auto is_gas = [&](int64_t v) { return r.outcome[v] == WarpOutcome::Gas; };
  const int64_t step[3] = {1, dims[0], dims[0] * dims[1]};
  auto neighbours = [&](int64_t v, auto&& visit) {
    const int64_t i = v % dims[0], j = (v / dims[0]) % dims[1], k = v / (dims[0] * dims[1]);
    const int64_t c[3] = {i, j, k};
    for (int a = 0; a < 3; ++a) {
      if (c[a] > 0) visit(v - step[a]);
      if (c[a] + 1 < dims[a]) visit(v + step[a]);
    }
  };
  // Pieces by breadth-first search; the small ones' voxels are collected.
  VoxelBits seen(n);
  std::vector<int64_t> small, queue;
  for (int64_t s = 0; s < n; ++s) {
    if (!is_gas(s) || seen.test(s)) continue;
    queue.assign(1, s);
    seen.set(s);
    for (std::size_t q = 0; q < queue.size(); ++q)
      neighbours(queue[q], [&](int64_t u) {
        if (is_gas(u) && !seen.test(u)) {
          seen.set(u);
          queue.push_back(u);
        }
      });
    if (int64_t(queue.size()) < min_voxels) {
      small.insert(small.end(), queue.begin(), queue.end());
      ++out.pieces;
    }
  }
  // Fill inward: each pass gives every small-piece voxel with a filled or non-gas neighbour that
  // neighbour's values (the first in the fixed order −i, +i, −j, +j, −k, +k), read before the pass.
  VoxelBits pending(n);
  for (int64_t v : small) pending.set(v);
  std::vector<std::pair<int64_t, int64_t>> updates;   // (voxel, source)
  bool progress = true;
  while (progress) {
    progress = false;
    updates.clear();
    for (int64_t v : small) {
      if (!pending.test(v)) continue;
      int64_t src = -1;
      neighbours(v, [&](int64_t u) {
        if (src < 0 && !pending.test(u) && !is_gas(u)) src = u;
      });
      if (src >= 0) updates.emplace_back(v, src);
    }
    for (auto [v, src] : updates) {
      r.ct_hu[v] = r.ct_hu[src];
      if (labels) r.labels[v] = r.labels[src];
      r.outcome[v] = WarpOutcome::Carried;
      pending.clear(v);
      ++out.voxels;
      progress = true;
    }
  }
  r.gas_voxels -= out.voxels;
  r.carried_voxels += out.voxels;
  return out;
}

}  // namespace pneumo
