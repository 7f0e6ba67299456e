#include "solve/symmetric_block_csr.h"

#include <algorithm>

namespace pneumo {

int64_t SymmetricBlockCsr::find(int32_t row, int32_t column) const {
  const auto first = col.begin() + row_start[row], last = col.begin() + row_start[row + 1];
  const auto it = std::lower_bound(first, last, column);
  return it != last && *it == column ? int64_t(it - col.begin()) : -1;
}

void SymmetricBlockCsr::plan_chunks() const {
  const int64_t R = rows();
  // The bandwidth: how far past its own row a row's transposed blocks reach.
  int64_t band = 0;
  for (int64_t r = 0; r < R; ++r)
    if (row_start[r + 1] > row_start[r]) band = std::max<int64_t>(band, col[row_start[r + 1] - 1] - r);
  // Chunks at least four bands long, so that each chunk's partial sums span at most about 1.25 times its
  // rows (zeroing and adding them costs about what one thread's full-length sums cost); at most about
  // kMaxChunks of them.
  const int64_t rows_per_chunk = std::max<int64_t>({4 * band, (R + kMaxChunks - 1) / kMaxChunks, 256});
  plan_.first.clear();
  plan_.reach.clear();
  plan_.offset.assign(1, 0);
  for (int64_t r0 = 0; r0 < R; r0 += rows_per_chunk) {
    const int64_t r1 = std::min(R, r0 + rows_per_chunk);
    int64_t reach = r1;
    for (int64_t r = r0; r < r1; ++r)
      if (row_start[r + 1] > row_start[r]) reach = std::max<int64_t>(reach, col[row_start[r + 1] - 1] + 1);
    plan_.first.push_back(r0);
    plan_.reach.push_back(reach);
    plan_.offset.push_back(plan_.offset.back() + (reach - r0));
  }
  plan_.first.push_back(R);
  // For each chunk, the first chunk whose partial sums reach into it.
  const int64_t C = int64_t(plan_.reach.size());
  plan_.lowest.assign(C, 0);
  for (int64_t k = 0; k < C; ++k) {
    int64_t lo = k;
    for (int64_t c = 0; c < k; ++c)
      if (plan_.reach[c] > plan_.first[k]) { lo = c; break; }
    plan_.lowest[k] = lo;
  }
  plan_.rows = R;
  plan_.entries = int64_t(col.size());
  plan_.partial.resize(plan_.offset.back());
}

void SymmetricBlockCsr::multiply(const std::vector<Vec3>& x, std::vector<Vec3>& y) const {
  const int64_t R = rows();
  y.resize(R);
  if (plan_.rows != R || plan_.entries != int64_t(col.size())) plan_chunks();
  const int64_t C = int64_t(plan_.reach.size());
  Vec3* const partial = plan_.partial.data();
  // Each chunk of rows adds its rows' upper blocks into y directly (its rows are its own) and their
  // transposes, which land in its own rows and up to a band beyond, into its own partial sums. Then
  // each row adds the partial sums that reach it in chunk order. The chunks are the matrix's, not the
  // threads': the sums, and so every bit of y, are the same at any thread count.
#pragma omp parallel if (R > 20000)
  {
#pragma omp for schedule(static, 1)
    for (int64_t c = 0; c < C; ++c) {
      const int64_t r0 = plan_.first[c];
      Vec3* const mine = partial + plan_.offset[c] - r0;   // mine[r] for r in [r0, reach)
      std::fill(partial + plan_.offset[c], partial + plan_.offset[c + 1], Vec3::Zero());
      for (int64_t r = r0; r < plan_.first[c + 1]; ++r) {
        Vec3 sum = Vec3::Zero();
        const Vec3 xr = x[r];
        for (int64_t k = row_start[r]; k < row_start[r + 1]; ++k) {
          const int32_t c_col = col[k];
          sum.noalias() += block[k] * x[c_col];
          if (c_col != r) mine[c_col].noalias() += block[k].transpose() * xr;
        }
        y[r] = sum;
      }
    }
#pragma omp for schedule(static, 1)
    for (int64_t k = 0; k < C; ++k)
      for (int64_t c = plan_.lowest[k]; c <= k; ++c) {   // each row's sums in chunk order
        const Vec3* const from = partial + plan_.offset[c] - plan_.first[c];
        const int64_t end = std::min(plan_.first[k + 1], plan_.reach[c]);
        for (int64_t r = plan_.first[k]; r < end; ++r) y[r] += from[r];
      }
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
