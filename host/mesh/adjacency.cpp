#include "mesh/adjacency.h"

namespace pneumo {

namespace {
template <std::size_t K>
Csr build(int64_t nodes, const std::vector<std::array<int32_t, K>>& elements) {
  Csr c;
  c.start.assign(nodes + 1, 0);
  for (const auto& e : elements)
    for (int32_t n : e) ++c.start[n + 1];
  for (int64_t n = 0; n < nodes; ++n) c.start[n + 1] += c.start[n];
  c.item.resize(c.start[nodes]);
  std::vector<int64_t> fill(c.start.begin(), c.start.end() - 1);
  for (std::size_t e = 0; e < elements.size(); ++e)
    for (std::size_t s = 0; s < K; ++s) c.item[fill[elements[e][s]]++] = int32_t(e * 8 + s);
  return c;
}
}  // namespace

Adjacency Adjacency::of(const Mesh& m) {
  Adjacency a;
  a.springs = build(m.node_count(), m.springs);
  a.tets = build(m.node_count(), m.tets);
  std::vector<std::array<int32_t, 4>> load_nodes(m.load_tet.size());
  for (std::size_t l = 0; l < load_nodes.size(); ++l) load_nodes[l] = m.tets[m.load_tet[l]];
  a.loads = build(m.node_count(), load_nodes);
  return a;
}

}  // namespace pneumo
