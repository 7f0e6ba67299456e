#include "solve/symmetric_block_csr.h"

#include <algorithm>

#include <omp.h>

namespace pneumo {

int64_t SymmetricBlockCsr::find(int32_t row, int32_t column) const {
  const auto first = col.begin() + row_start[row], last = col.begin() + row_start[row + 1];
  const auto it = std::lower_bound(first, last, column);
  return it != last && *it == column ? int64_t(it - col.begin()) : -1;
}

void SymmetricBlockCsr::multiply(const std::vector<Vec3>& x, std::vector<Vec3>& y) const {
  const int64_t R = rows();
  y.resize(R);
  const int threads = R > 20000 ? omp_get_max_threads() : 1;
  partial_.resize(threads);
  // Each thread adds its rows' upper blocks into y directly (its rows are its own) and their
  // transposes, which land in other rows, into its own partial sums; the partial sums are added last.
#pragma omp parallel num_threads(threads)
  {
    const int team = omp_get_num_threads();   // at most `threads`: only these partial sums are fresh
    std::vector<Vec3>& mine = partial_[omp_get_thread_num()];
    mine.assign(R, Vec3::Zero());
#pragma omp for schedule(static)
    for (int64_t r = 0; r < R; ++r) {
      Vec3 sum = Vec3::Zero();
      const Vec3 xr = x[r];
      for (int64_t k = row_start[r]; k < row_start[r + 1]; ++k) {
        const int32_t c = col[k];
        sum.noalias() += block[k] * x[c];
        if (c != r) mine[c].noalias() += block[k].transpose() * xr;
      }
      y[r] = sum;
    }
#pragma omp for schedule(static)
    for (int64_t r = 0; r < R; ++r)
      for (int t = 0; t < team; ++t) y[r] += partial_[t][r];
  }
}

SymmetricBlockCsr symmetric_pattern_of_groups(int64_t node_count, const std::vector<int64_t>& begin,
                                              const std::vector<int32_t>& nodes) {
  const int64_t G = int64_t(begin.size()) - 1;
  // Each node's candidates: the nodes of every group it belongs to, itself and above (duplicates
  // removed below).
  std::vector<int64_t> count(node_count + 1, 0);
  for (int64_t g = 0; g < G; ++g)
    for (int64_t i = begin[g]; i < begin[g + 1]; ++i) count[nodes[i] + 1] += begin[g + 1] - begin[g];
  for (int64_t n = 0; n < node_count; ++n) count[n + 1] += count[n];
  std::vector<int32_t> candidates(count[node_count]);
  std::vector<int64_t> fill(count.begin(), count.end() - 1);
  for (int64_t g = 0; g < G; ++g)
    for (int64_t i = begin[g]; i < begin[g + 1]; ++i)
      for (int64_t j = begin[g]; j < begin[g + 1]; ++j)
        if (nodes[j] >= nodes[i]) candidates[fill[nodes[i]]++] = nodes[j];
  SymmetricBlockCsr a;
  a.row_start.assign(node_count + 1, 0);
  for (int64_t n = 0; n < node_count; ++n) {
    const auto first = candidates.begin() + count[n], last = candidates.begin() + fill[n];
    std::sort(first, last);
    const auto end = std::unique(first, last);
    a.col.insert(a.col.end(), first, end);
    a.row_start[n + 1] = int64_t(a.col.size());
  }
  a.block.assign(a.col.size(), Mat3::Zero());
  return a;
}

}  // namespace pneumo
