#include "solve/forces_cl.h"

#include <algorithm>

#include "mesh/adjacency.h"

namespace pneumo {

namespace {

constexpr std::size_t kLocal = ocl::kWorkGroupSize;
constexpr int kBlock = 8;            // nodes per work-item in node_forces (W in msd_forces.cl)

int max_degree(const Csr& c, int64_t nodes) {
  int64_t d = 0;
  for (int64_t n = 0; n < nodes; ++n) d = std::max(d, c.end(n) - c.begin(n));
  return int(std::max<int64_t>(d, 1));
}

int64_t degree(const Csr& c, int64_t n) { return c.end(n) - c.begin(n); }

/// Nodes grouped into blocks of kBlock: nodes with a free axis first, fully held ones last (their
/// blocks can be skipped when only free forces matter). Within windows of kWindow nodes in mesh
/// (lattice) order, nodes are sorted by spring degree, then pressure-load and tetrahedron degree,
/// so a block's nodes need about the same number of records while a pass still sweeps the lattice
/// once: the neighbours a block gathers stay within a few lattice planes, in cache, on meshes far
/// larger than the cache (a global sort would sweep it once per degree).
std::vector<int> block_nodes(const Mesh& m, const Adjacency& adj, int64_t& free_blocks) {
  constexpr std::size_t kWindow = 1024;
  std::vector<int> free_nodes, held_nodes;
  for (int64_t n = 0; n < m.node_count(); ++n) (m.hold[n] == kHoldAll ? held_nodes : free_nodes).push_back(int(n));
  auto key = [&](int n) {
    return std::array<int64_t, 3>{degree(adj.springs, n), degree(adj.loads, n), degree(adj.tets, n)};
  };
  std::vector<int> order;
  for (std::vector<int>* part : {&free_nodes, &held_nodes}) {
    for (std::size_t w = 0; w < part->size(); w += kWindow) {
      const auto first = part->begin() + w, last = part->begin() + std::min(part->size(), w + kWindow);
      std::stable_sort(first, last, [&](int a, int b) { return key(a) > key(b); });
    }
    order.insert(order.end(), part->begin(), part->end());
    // Each part starts a block of its own: −1 pads its last block.
    order.resize((order.size() + kBlock - 1) / kBlock * kBlock, -1);
    if (part == &free_nodes) free_blocks = int64_t(order.size()) / kBlock;
  }
  return order;
}

/// Block-record tables of one adjacency: records begin[b] … begin[b + 1] − 1 are block b's, as
/// many as its widest node's degree, each kBlock entries (one per lane).
std::vector<int> block_begin(const Csr& c, const std::vector<int>& blocks) {
  const int64_t n_blocks = int64_t(blocks.size()) / kBlock;
  std::vector<int> begin(n_blocks + 1, 0);
  for (int64_t b = 0; b < n_blocks; ++b) {
    int64_t width = 0;
    for (int l = 0; l < kBlock; ++l)
      if (const int n = blocks[b * kBlock + l]; n >= 0) width = std::max(width, degree(c, n));
    begin[b + 1] = begin[b] + int(width);
  }
  return begin;
}

/// Calls fill(entry, node, item) for each real entry and pad(entry, node) for each padding one
/// (node: the lane's node, or node 0 for the lanes past the last node).
template <class Fill, class Pad>
void fill_block_table(const Csr& c, const std::vector<int>& blocks, const std::vector<int>& begin, Fill&& fill,
                      Pad&& pad) {
  for (std::size_t b = 0; b + 1 < begin.size(); ++b)
    for (int r = begin[b]; r < begin[b + 1]; ++r)
      for (int l = 0; l < kBlock; ++l) {
        const int n = blocks[b * kBlock + l];
        const std::size_t entry = std::size_t(r) * kBlock + l;
        const int64_t slot = r - begin[b];
        if (n >= 0 && slot < degree(c, n)) fill(entry, n, c.item[c.begin(n) + slot]);
        else pad(entry, std::max(n, 0));
      }
}

struct DeviceBytes {
  uint64_t total = 0, largest = 0;
};

/// Everything the evaluator allocates, before any of it is: node state (u, v, x₀, F: float4; mass;
/// the block's nodes), the block tables (per record and lane: spring end, k, c, rest x/y/z/length: 28
/// bytes; load or tetrahedron force index: 4 bytes; and where each block's records begin), the
/// pressure loads (nodes, 4 vectors, 4 forces) and tetrahedra (nodes, fraction, 4 forces), with the
/// zero entry past the last. The records are bounded by the widest block's: at most max degree per node.
DeviceBytes evaluator_bytes(const Adjacency& adj, const std::vector<int>& blocks, int64_t nodes, int64_t loads,
                            int64_t tets, uint64_t extra_bytes_per_node) {
  const uint64_t N = uint64_t(blocks.size()), T = uint64_t(tets), R = uint64_t(loads);
  const uint64_t block_begins = 3 * (N / kBlock + 1) * 4;
  const uint64_t spring_entries = uint64_t(max_degree(adj.springs, nodes)) * N;
  DeviceBytes b;
  b.total = N * (4 * 16 + 4 + 4 + extra_bytes_per_node) + block_begins + spring_entries * 28 +
            R * (16 + 64) + (R + 1) * 64 + uint64_t(max_degree(adj.loads, nodes)) * N * 4 + T * 4 +
            (T + 1) * (16 + 64) + uint64_t(max_degree(adj.tets, nodes)) * N * 4;
  b.largest = std::max({spring_entries * 4, (T + 1) * 64, (R + 1) * 64, N * 16});
  return b;
}

}  // namespace

uint64_t ClForceEvaluator::device_bytes(const Mesh& m, uint64_t extra_bytes_per_node) {
  const Adjacency adj = Adjacency::of(m);
  int64_t free_blocks = 0;
  return evaluator_bytes(adj, block_nodes(m, adj, free_blocks), m.node_count(), int64_t(m.load_tet.size()),
                         int64_t(m.tets.size()), extra_bytes_per_node)
      .total;
}

std::vector<cl_float4> to_float4(const std::vector<Vec3>& v) {
  std::vector<cl_float4> out(v.size());
  for (std::size_t i = 0; i < v.size(); ++i) out[i] = {{float(v[i][0]), float(v[i][1]), float(v[i][2]), 0.0f}};
  return out;
}

ClForceEvaluator::ClForceEvaluator(ocl::Context& ctx, const Mesh& m, uint64_t extra_bytes_per_node)
    : ctx_(ctx), nodes_(m.node_count()), loads_(int64_t(m.load_tet.size())), tets_(int64_t(m.tets.size())) {
  const Adjacency adj = Adjacency::of(m);
  const std::vector<int> blocks = block_nodes(m, adj, free_blocks_);
  blocks_ = int64_t(blocks.size()) / kBlock;
  const DeviceBytes needs = evaluator_bytes(adj, blocks, nodes_, loads_, tets_, extra_bytes_per_node);
  ctx.check_fits(needs.total, needs.largest, "this mesh (" + std::to_string(nodes_) + " nodes)");

  // Springs seen from each node: the other end, the spring's constants, the rest vector from the
  // other end to this node (in double, then rounded) and the length of that rounded vector.
  const std::vector<int> spring_begin = block_begin(adj.springs, blocks);
  const std::size_t entries = std::size_t(spring_begin.back()) * kBlock;
  std::vector<int> other(entries);
  std::vector<float> k(entries), c(entries), rx(entries), ry(entries), rz(entries), rl(entries);
  fill_block_table(
      adj.springs, blocks, spring_begin,
      [&](std::size_t e, int n, int32_t item) {
        const int s = item / 8, slot = item % 8;
        const int j = m.springs[s][1 - slot];
        other[e] = j;
        k[e] = float(m.spring_k[s]);
        c[e] = float(m.spring_c[s]);
        const Vec3 d0 = m.rest_m[n] - m.rest_m[j];
        rx[e] = float(d0[0]);
        ry[e] = float(d0[1]);
        rz[e] = float(d0[2]);
        rl[e] = float(d0.cast<float>().cast<double>().norm());
      },
      [&](std::size_t e, int n) {
        other[e] = n;
        k[e] = c[e] = 0.0f;
        rx[e] = rl[e] = 1.0f;   // a unit rest vector: finite arithmetic, zero force
        ry[e] = rz[e] = 0.0f;
      });
  spring_begin_host_ = spring_begin;
  block_nodes_ = upload(ctx, blocks);
  spring_begin_ = upload(ctx, spring_begin);
  spring_node_ = upload(ctx, other);
  spring_k_ = upload(ctx, k);
  spring_c_ = upload(ctx, c);
  spring_rest_[0] = upload(ctx, rx);
  spring_rest_[1] = upload(ctx, ry);
  spring_rest_[2] = upload(ctx, rz);
  spring_rest_[3] = upload(ctx, rl);

  // Element forces gathered per node; padding points at the zero entry past the last element.
  auto element_table = [&](const Csr& csr, int zero_entry, auto&& index_of, cl::Buffer& begin_buf,
                           cl::Buffer& table_buf) {
    const std::vector<int> begin = block_begin(csr, blocks);
    std::vector<int> table(std::size_t(begin.back()) * kBlock);
    fill_block_table(
        csr, blocks, begin, [&](std::size_t e, int, int32_t item) { table[e] = index_of(item); },
        [&](std::size_t e, int) { table[e] = zero_entry; });
    begin_buf = upload(ctx, begin);
    table_buf = upload(ctx, table);
  };
  element_table(adj.loads, int(4 * loads_), [](int32_t it) { return 4 * (it / 8) + it % 8; }, load_begin_, node_load_);
  element_table(adj.tets, int(4 * tets_), [](int32_t it) { return 4 * (it / 8) + it % 8; }, tet_begin_, node_tet_);

  std::vector<cl_int4> load_nodes(std::max<int64_t>(loads_, 1), cl_int4{{0, 0, 0, 0}}), tets(m.tets.size());
  std::vector<cl_float4> load_c(4 * load_nodes.size(), cl_float4{{0, 0, 0, 0}});
  for (int64_t l = 0; l < loads_; ++l) {
    const auto& q = m.tets[m.load_tet[l]];
    load_nodes[l] = {{q[0], q[1], q[2], q[3]}};
    for (int i = 0; i < 4; ++i) {
      const Vec3& c = m.load_c[l][i];
      load_c[4 * l + i] = {{float(c[0]), float(c[1]), float(c[2]), 0.0f}};
    }
  }
  for (std::size_t t = 0; t < tets.size(); ++t) tets[t] = {{m.tets[t][0], m.tets[t][1], m.tets[t][2], m.tets[t][3]}};
  std::vector<float> fraction(std::max<std::size_t>(m.tets.size(), 1), 1.0f);
  for (std::size_t t = 0; t < m.tet_fraction.size(); ++t) fraction[t] = float(m.tet_fraction[t]);
  load_nodes_ = upload(ctx, load_nodes);
  load_c_ = upload(ctx, load_c);
  tets_buf_ = upload(ctx, tets);
  tet_fraction_ = upload(ctx, fraction);
  std::vector<float> mass(nodes_, 0.f);
  for (int64_t n = 0; n < nodes_ && !m.mass_kg.empty(); ++n) mass[n] = float(m.mass_kg[n]);
  mass_ = upload(ctx, mass);
  rest_x_ = upload(ctx, to_float4(m.rest_m));
  rest_m_ = m.rest_m;
  x_ = upload(ctx, std::vector<cl_float4>(nodes_, cl_float4{{0, 0, 0, 0}}), CL_MEM_READ_WRITE);
  v_ = upload(ctx, std::vector<cl_float4>(nodes_, cl_float4{{0, 0, 0, 0}}), CL_MEM_READ_WRITE);
  // Zeroed: a free-nodes-only evaluation leaves the fully held nodes' entries as they are.
  f_ = upload(ctx, std::vector<cl_float4>(nodes_, cl_float4{{0, 0, 0, 0}}), CL_MEM_READ_WRITE);
  // One zero entry past the last element: the padding's target. Zeroed once, so a term that is
  // switched off also adds exact zeros.
  load_force_ = cl::Buffer(ctx.context(), CL_MEM_READ_WRITE, std::size_t(4 * loads_ + 1) * sizeof(cl_float4));
  tet_force_ = cl::Buffer(ctx.context(), CL_MEM_READ_WRITE, std::size_t(4 * tets_ + 1) * sizeof(cl_float4));
  ctx.queue().enqueueFillBuffer(load_force_, cl_float4{{0, 0, 0, 0}}, 0, std::size_t(4 * loads_ + 1) * sizeof(cl_float4));
  ctx.queue().enqueueFillBuffer(tet_force_, cl_float4{{0, 0, 0, 0}}, 0, std::size_t(4 * tets_ + 1) * sizeof(cl_float4));

  const std::string options = "-DW=" + std::to_string(kBlock);
  k_load_ = ctx.kernel("msd_forces.cl", "load_pressure", options);
  k_tet_ = ctx.kernel("msd_forces.cl", "tet_volume", options);
  k_node_ = ctx.kernel("msd_forces.cl", "node_forces", options);
}

double ClForceEvaluator::spring_records_per_node(Nodes which) const {
  const int64_t records = which == Nodes::All ? spring_begin_host_.back() : spring_begin_host_[free_blocks_];
  return double(records) * kBlock / double(std::max<int64_t>(nodes_, 1));
}

double ClForceEvaluator::gathered_fraction(Nodes which) const {
  return which == Nodes::All ? 1.0 : double(free_blocks_) / double(std::max<int64_t>(blocks_, 1));
}

void ClForceEvaluator::upload_state(const std::vector<Vec3>& x, const std::vector<Vec3>& v) {
  auto& q = ctx_.queue();
  std::vector<Vec3> u(nodes_);
  for (int64_t n = 0; n < nodes_; ++n) u[n] = x[n] - rest_m_[n];   // in double, then rounded
  q.enqueueWriteBuffer(x_, CL_TRUE, 0, nodes_ * sizeof(cl_float4), to_float4(u).data());
  if (!v.empty()) q.enqueueWriteBuffer(v_, CL_TRUE, 0, nodes_ * sizeof(cl_float4), to_float4(v).data());
}

void ClForceEvaluator::evaluate(const ForceModel& model, Nodes which) {
  auto& q = ctx_.queue();
  const bool pressure = model.pressure_pa != 0.0 && loads_ > 0, volume = model.volume_stiffness_pa != 0.0;
  if (pressure) {
    ocl::set_args(k_load_, x_, rest_x_, load_nodes_, load_c_, float(model.pressure_pa), cl_int(loads_), load_force_);
    q.enqueueNDRangeKernel(k_load_, cl::NullRange, cl::NDRange(ocl::global_size(loads_)), cl::NDRange(kLocal));
  }
  if (volume) {
    ocl::set_args(k_tet_, x_, rest_x_, tets_buf_, tet_fraction_, float(model.volume_stiffness_pa), cl_int(tets_),
                  tet_force_);
    q.enqueueNDRangeKernel(k_tet_, cl::NullRange, cl::NDRange(ocl::global_size(tets_)), cl::NDRange(kLocal));
  }
  const int64_t blocks = which == Nodes::All ? blocks_ : free_blocks_;
  ocl::set_args(k_node_, x_, v_, mass_, cl_int(blocks), block_nodes_, spring_begin_, spring_node_, spring_k_,
                spring_c_, spring_rest_[0], spring_rest_[1], spring_rest_[2], spring_rest_[3],
                cl_int(model.spring_model == SpringModel::Linear), cl_int(model.damping), float(model.stiffening), load_force_, load_begin_,
                node_load_, cl_int(pressure), tet_force_, tet_begin_, node_tet_, cl_int(volume),
                cl_float4{{float(model.gravity_m_s2[0]), float(model.gravity_m_s2[1]), float(model.gravity_m_s2[2]), 0.0f}},
                f_);
  if (blocks > 0)
    q.enqueueNDRangeKernel(k_node_, cl::NullRange, cl::NDRange(ocl::global_size(blocks)), cl::NDRange(kLocal));
}

std::vector<Vec3> ClForceEvaluator::download_positions(cl::Buffer& u) {
  std::vector<cl_float4> raw(nodes_);
  ctx_.queue().enqueueReadBuffer(u, CL_TRUE, 0, nodes_ * sizeof(cl_float4), raw.data());
  std::vector<Vec3> x(nodes_);
  for (int64_t n = 0; n < nodes_; ++n) x[n] = rest_m_[n] + Vec3(raw[n].s[0], raw[n].s[1], raw[n].s[2]);
  return x;
}

void ClForceEvaluator::download_forces(std::vector<Vec3>& f) {
  std::vector<cl_float4> raw(nodes_);
  ctx_.queue().enqueueReadBuffer(f_, CL_TRUE, 0, nodes_ * sizeof(cl_float4), raw.data());
  f.resize(nodes_);
  for (int64_t n = 0; n < nodes_; ++n) f[n] = Vec3(raw[n].s[0], raw[n].s[1], raw[n].s[2]);
}

}  // namespace pneumo
