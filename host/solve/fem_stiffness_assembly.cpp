#include "solve/fem_stiffness_assembly.h"

#include <algorithm>
#include <array>
#include <stdexcept>

namespace pneumo {

namespace {

// A group is one cube's tetrahedra of one part (8 corners) or one tetrahedron (4); the bound only
// sizes a stack array.
constexpr int64_t kMaxGroupNodes = 64;
// Groups are assembled in chunks of about this many local blocks (9 MB), each chunk in parallel into
// its own buffer, then added into K in order: no two threads add into one block.
constexpr int64_t kChunkBlocks = 1 << 17;

// Each group's distinct nodes, ascending: group g's are nodes[begin[g]] … nodes[begin[g + 1] − 1].
void distinct_nodes_of_groups(const Mesh& m, const FemGroups& groups, std::vector<int64_t>& begin,
                              std::vector<int32_t>& nodes) {
  const int64_t G = int64_t(groups.begin.size()) - 1;
  begin.assign(1, 0);
  nodes.clear();
  for (int64_t g = 0; g < G; ++g) {
    const std::size_t first = nodes.size();
    for (int32_t i = groups.begin[g]; i < groups.begin[g + 1]; ++i)
      for (int32_t v : m.tets[groups.tets[i]]) nodes.push_back(v);
    std::sort(nodes.begin() + first, nodes.end());
    nodes.erase(std::unique(nodes.begin() + first, nodes.end()), nodes.end());
    begin.push_back(int64_t(nodes.size()));
  }
}

}  // namespace

std::optional<FemStiffnessAssembly> FemStiffnessAssembly::within(const Mesh& m, const FemGroups& groups,
                                                                  int64_t budget_bytes) {
  FemStiffnessAssembly a;
  distinct_nodes_of_groups(m, groups, a.node_begin_, a.nodes_);
  const int64_t G = int64_t(a.node_begin_.size()) - 1;
  int64_t blocks = 0;
  for (int64_t g = 0; g < G; ++g) {
    const int64_t n = a.node_begin_[g + 1] - a.node_begin_[g];
    if (n > kMaxGroupNodes) throw std::logic_error("FemStiffnessAssembly: a group with more than 64 nodes");
    blocks += n * (n + 1) / 2;
  }
  if (blocks * int64_t(sizeof(Mat3) + sizeof(int32_t)) > budget_bytes) return std::nullopt;
  a.k_ = symmetric_pattern_of_groups(m.node_count(), a.node_begin_, a.nodes_);
  a.slot_begin_.assign(1, 0);
  for (int64_t g = 0; g < G; ++g) {
    const int64_t n = a.node_begin_[g + 1] - a.node_begin_[g];
    for (int64_t r = 0; r < n; ++r)
      for (int64_t c = 0; c < n; ++c)   // the nodes ascend, so r > c is below the diagonal
        a.slot_.push_back(r > c ? -1 : a.k_.find(a.nodes_[a.node_begin_[g] + r], a.nodes_[a.node_begin_[g] + c]));
    a.slot_begin_.push_back(int64_t(a.slot_.size()));
  }
  a.local_.resize(4 * m.tets.size());
  for (int64_t g = 0; g < G; ++g) {
    const auto first = a.nodes_.begin() + a.node_begin_[g], last = a.nodes_.begin() + a.node_begin_[g + 1];
    for (int32_t i = groups.begin[g]; i < groups.begin[g + 1]; ++i) {
      const int32_t t = groups.tets[i];
      for (int v = 0; v < 4; ++v) a.local_[4 * t + v] = uint8_t(std::lower_bound(first, last, m.tets[t][v]) - first);
    }
  }
  return a;
}

void FemStiffnessAssembly::assemble(const FemTets& tets, const FemGroups& groups, const std::vector<ElementState>& state,
                                    const std::vector<double>& ebar) {
  for (Mat3& b : k_.block) b.setZero();
  const int64_t G = int64_t(node_begin_.size()) - 1;
  std::vector<Mat3> local;
  for (int64_t g0 = 0; g0 < G;) {
    int64_t g1 = g0 + 1;
    while (g1 < G && slot_begin_[g1 + 1] - slot_begin_[g0] <= kChunkBlocks) ++g1;
    local.assign(slot_begin_[g1] - slot_begin_[g0], Mat3::Zero());
#pragma omp parallel for schedule(dynamic, 64) if (g1 - g0 > 256)
    for (int64_t g = g0; g < g1; ++g) {
      const int64_t n = node_begin_[g + 1] - node_begin_[g];
      Mat3* out = local.data() + (slot_begin_[g] - slot_begin_[g0]);
      std::array<Vec3, kMaxGroupNodes> b_c;
      std::fill(b_c.begin(), b_c.begin() + n, Vec3::Zero());
      for (int32_t k = groups.begin[g]; k < groups.begin[g + 1]; ++k) {
        const int32_t t = groups.tets[k];
        const ElementState& s = state[t];
        const double volume = tets.rest[t].volume_m3, kappa = tets.kappa[t];
        const std::array<Vec3, 4> grad = shape_gradients(tets.rest[t]);
        const Mat3 G_t = dilatation_gradient(s);
        for (int j = 0; j < 4; ++j) {
          const int64_t lj = local_[4 * t + j];
          for (int axis = 0; axis < 3; ++axis) {
            const Mat3 dF = Vec3::Unit(axis) * grad[j].transpose();
            const Mat3 dP = deviatoric_dpiola(s, dF, tets.material[t]) + kappa * ebar[g] * dilatation_dgradient(s, dF);
            for (int i = 0; i < 4; ++i) out[local_[4 * t + i] * n + lj].col(axis) += volume * dP * grad[i];
          }
        }
        for (int i = 0; i < 4; ++i) b_c[local_[4 * t + i]] += kappa * volume * G_t * grad[i];
      }
      if (groups.weight[g] > 0.0)
        for (int64_t a = 0; a < n; ++a)
          for (int64_t c = 0; c < n; ++c) out[a * n + c] += b_c[a] * b_c[c].transpose() / groups.weight[g];
    }
    for (int64_t s = slot_begin_[g0]; s < slot_begin_[g1]; ++s)
      if (slot_[s] >= 0) k_.block[slot_[s]] += local[s - slot_begin_[g0]];
    g0 = g1;
  }
}

}  // namespace pneumo
