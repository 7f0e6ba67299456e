#include "anatomy/connected_components.h"

#include <algorithm>
#include <numeric>

namespace pneumo {

namespace {

struct Run {
  int32_t start, end;  // [start, end) along i
};

struct UnionFind {
  std::vector<int64_t> parent;
  explicit UnionFind(int64_t n) : parent(static_cast<std::size_t>(n)) { std::iota(parent.begin(), parent.end(), 0); }
  int64_t find(int64_t x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  }
  void unite(int64_t a, int64_t b) {
    a = find(a);
    b = find(b);
    if (a != b) parent[std::max(a, b)] = std::min(a, b);
  }
};

/// Runs of each row (j, k); row_begin[r]..row_begin[r+1] index `runs`. Rows are independent, so
/// they are found in parallel per slice k and concatenated.
void find_runs(const std::vector<uint8_t>& mask, const Index3& d, std::vector<Run>& runs,
               std::vector<int64_t>& row_begin) {
  const int64_t rows = d[1] * d[2];
  std::vector<std::vector<Run>> per_slice(static_cast<std::size_t>(d[2]));
  std::vector<int32_t> count(static_cast<std::size_t>(rows), 0);
#pragma omp parallel for schedule(dynamic, 4)
  for (int64_t k = 0; k < d[2]; ++k) {
    for (int64_t j = 0; j < d[1]; ++j) {
      const uint8_t* row = mask.data() + d[0] * (j + d[1] * k);
      int32_t n = 0;
      for (int64_t i = 0; i < d[0];) {
        if (!row[i]) { ++i; continue; }
        const int64_t s = i;
        while (i < d[0] && row[i]) ++i;
        per_slice[k].push_back({int32_t(s), int32_t(i)});
        ++n;
      }
      count[j + d[1] * k] = n;
    }
  }
  row_begin.assign(std::size_t(rows) + 1, 0);
  for (int64_t r = 0; r < rows; ++r) row_begin[r + 1] = row_begin[r] + count[r];
  runs.clear();
  runs.reserve(static_cast<std::size_t>(row_begin[rows]));
  for (auto& s : per_slice) runs.insert(runs.end(), s.begin(), s.end());
}

/// Unites overlapping runs of two rows (6-connectivity: they share at least one i).
void unite_rows(const std::vector<Run>& runs, int64_t a0, int64_t a1, int64_t b0, int64_t b1, UnionFind& uf) {
  int64_t a = a0, b = b0;
  while (a < a1 && b < b1) {
    if (runs[a].start < runs[b].end && runs[b].start < runs[a].end) uf.unite(a, b);
    if (runs[a].end < runs[b].end) ++a;
    else ++b;
  }
}

}  // namespace

int64_t keep_largest_component(std::vector<uint8_t>& mask, const Index3& d) {
  std::vector<Run> runs;
  std::vector<int64_t> row_begin;
  find_runs(mask, d, runs, row_begin);
  const int64_t n_runs = int64_t(runs.size());
  if (n_runs == 0) return 0;

  UnionFind uf(n_runs);
  for (int64_t k = 0; k < d[2]; ++k)
    for (int64_t j = 0; j < d[1]; ++j) {
      const int64_t r = j + d[1] * k;
      if (j > 0) unite_rows(runs, row_begin[r], row_begin[r + 1], row_begin[r - 1], row_begin[r], uf);
      if (k > 0) unite_rows(runs, row_begin[r], row_begin[r + 1], row_begin[r - d[1]], row_begin[r - d[1] + 1], uf);
    }

  std::vector<int64_t> size(static_cast<std::size_t>(n_runs), 0);
  for (int64_t r = 0; r < n_runs; ++r) size[uf.find(r)] += runs[r].end - runs[r].start;
  const int64_t best = std::max_element(size.begin(), size.end()) - size.begin();
  std::vector<uint8_t> keep(static_cast<std::size_t>(n_runs));
  for (int64_t r = 0; r < n_runs; ++r) keep[r] = uf.find(r) == best;  // serial: find() compresses paths

  // Clear the runs of every other component, row by row.
  const int64_t rows = d[1] * d[2];
#pragma omp parallel for schedule(static)
  for (int64_t r = 0; r < rows; ++r)
    for (int64_t q = row_begin[r]; q < row_begin[r + 1]; ++q)
      if (!keep[q])
        std::fill(mask.begin() + d[0] * r + runs[q].start, mask.begin() + d[0] * r + runs[q].end, 0);
  return size[best];
}

}  // namespace pneumo
