#include "warp/cavity_specks.h"

#include <vector>

namespace pneumo {

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
  std::vector<int32_t> piece(std::size_t(n), -1);
  std::vector<int64_t> small, queue;
  int32_t pieces = 0;
  for (int64_t s = 0; s < n; ++s) {
    if (!is_gas(s) || piece[s] >= 0) continue;
    queue.assign(1, s);
    piece[s] = pieces;
    for (std::size_t q = 0; q < queue.size(); ++q)
      neighbours(queue[q], [&](int64_t u) {
        if (is_gas(u) && piece[u] < 0) {
          piece[u] = pieces;
          queue.push_back(u);
        }
      });
    if (int64_t(queue.size()) < min_voxels) {
      small.insert(small.end(), queue.begin(), queue.end());
      ++out.pieces;
    }
    ++pieces;
  }
  // Fill inward: each pass gives every small-piece voxel with a filled or non-gas neighbour that
  // neighbour's values (the first in the fixed order −i, +i, −j, +j, −k, +k), read before the pass.
  std::vector<uint8_t> pending(std::size_t(n), 0);
  for (int64_t v : small) pending[v] = 1;
  std::vector<std::pair<int64_t, int64_t>> updates;   // (voxel, source)
  bool progress = true;
  while (progress) {
    progress = false;
    updates.clear();
    for (int64_t v : small) {
      if (!pending[v]) continue;
      int64_t src = -1;
      neighbours(v, [&](int64_t u) {
        if (src < 0 && !pending[u] && !is_gas(u)) src = u;
      });
      if (src >= 0) updates.emplace_back(v, src);
    }
    for (auto [v, src] : updates) {
      r.ct_hu[v] = r.ct_hu[src];
      if (labels) r.labels[v] = r.labels[src];
      r.outcome[v] = WarpOutcome::Carried;
      pending[v] = 0;
      ++out.voxels;
      progress = true;
    }
  }
  r.gas_voxels -= out.voxels;
  r.carried_voxels += out.voxels;
  return out;
}

}  // namespace pneumo
