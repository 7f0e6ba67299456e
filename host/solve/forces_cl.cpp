#include "solve/forces_cl.h"

#include <algorithm>

#include "mesh/adjacency.h"

namespace pneumo {

namespace {

constexpr std::size_t kLocal = 64;   // fixed work-group size: PoCL compiles once per (kernel, size)

std::size_t global_size(int64_t n) { return (std::size_t(n) + kLocal - 1) / kLocal * kLocal; }

int max_degree(const Csr& c, int64_t nodes) {
  int64_t d = 0;
  for (int64_t n = 0; n < nodes; ++n) d = std::max(d, c.end(n) - c.begin(n));
  return int(std::max<int64_t>(d, 1));
}

/// Slot-major padded table: out[slot * nodes + node] = value(node's slot-th entry), −1 past the end.
template <class F>
std::vector<int> padded_table(const Csr& c, int64_t nodes, int slots, F&& value) {
  std::vector<int> t(std::size_t(slots) * nodes, -1);
  for (int64_t n = 0; n < nodes; ++n)
    for (int64_t e = c.begin(n); e < c.end(n); ++e) t[std::size_t(e - c.begin(n)) * nodes + n] = value(c.item[e]);
  return t;
}

template <class T>
cl::Buffer upload(ocl::Context& ctx, const std::vector<T>& data, cl_mem_flags flags = CL_MEM_READ_ONLY) {
  const std::size_t bytes = std::max<std::size_t>(data.size() * sizeof(T), sizeof(T));
  cl::Buffer b(ctx.context(), flags, bytes);
  if (!data.empty()) ctx.queue().enqueueWriteBuffer(b, CL_TRUE, 0, data.size() * sizeof(T), data.data());
  return b;
}

}  // namespace

std::vector<cl_float4> to_float4(const std::vector<Vec3>& v) {
  std::vector<cl_float4> out(v.size());
  for (std::size_t i = 0; i < v.size(); ++i) out[i] = {{float(v[i][0]), float(v[i][1]), float(v[i][2]), 0.0f}};
  return out;
}

ClForceEvaluator::ClForceEvaluator(ocl::Context& ctx, const Mesh& m, uint64_t extra_bytes_per_node)
    : ctx_(ctx), nodes_(m.node_count()), tris_(int64_t(m.cavity_tris.size())), tets_(int64_t(m.tets.size())) {
  const Adjacency adj = Adjacency::of(m);
  spring_slots_ = max_degree(adj.springs, nodes_);
  tri_slots_ = max_degree(adj.tris, nodes_);
  tet_slots_ = max_degree(adj.tets, nodes_);
  {
    // Everything below, before any of it is allocated: node state (u, v, x₀, F: float4; mass), the
    // spring table (index, k, c: 4 bytes each; rest vector: 16 per slot), triangles and their
    // forces, tetrahedra and their 4 vertex forces, the two padded element tables.
    const uint64_t N = uint64_t(nodes_), T = uint64_t(tets_), R = uint64_t(tris_);
    const uint64_t spring_table = uint64_t(spring_slots_) * N;
    const uint64_t total = N * (4 * 16 + 4 + extra_bytes_per_node) + spring_table * 28 + R * 32 +
                           uint64_t(tri_slots_) * N * 4 + T * (16 + 64) + uint64_t(tet_slots_) * N * 4;
    const uint64_t largest = std::max({spring_table * 16, T * 64, N * 16});
    ctx.check_fits(total, largest, "this mesh (" + std::to_string(nodes_) + " nodes)");
  }

  // Springs seen from each node: the other end, and the spring's constants.
  const std::vector<int> spring_of = padded_table(adj.springs, nodes_, spring_slots_, [](int32_t it) { return it; });
  std::vector<int> other(spring_of.size(), -1);
  std::vector<float> k(spring_of.size(), 0.f), c(spring_of.size(), 0.f);
  std::vector<cl_float4> rest(spring_of.size(), cl_float4{{0, 0, 0, 0}});
  for (std::size_t e = 0; e < spring_of.size(); ++e) {
    if (spring_of[e] < 0) continue;
    const int s = spring_of[e] / 8, slot = spring_of[e] % 8;
    other[e] = m.springs[s][1 - slot];
    k[e] = float(m.spring_k[s]);
    c[e] = float(m.spring_c[s]);
    const Vec3 d0 = m.rest_m[m.springs[s][slot]] - m.rest_m[m.springs[s][1 - slot]];   // in double, then rounded
    const Vec3 d0f = d0.cast<float>().cast<double>();
    rest[e] = {{float(d0[0]), float(d0[1]), float(d0[2]), float(d0f.norm())}};
  }
  spring_node_ = upload(ctx, other);
  spring_k_ = upload(ctx, k);
  spring_c_ = upload(ctx, c);
  spring_rest_ = upload(ctx, rest);
  node_tri_ = upload(ctx, padded_table(adj.tris, nodes_, tri_slots_, [](int32_t it) { return it / 8; }));
  node_tet_ = upload(ctx, padded_table(adj.tets, nodes_, tet_slots_, [](int32_t it) { return 4 * (it / 8) + it % 8; }));

  std::vector<cl_int4> tris(m.cavity_tris.size()), tets(m.tets.size());
  for (std::size_t t = 0; t < tris.size(); ++t)
    tris[t] = {{m.cavity_tris[t][0], m.cavity_tris[t][1], m.cavity_tris[t][2], 0}};
  for (std::size_t t = 0; t < tets.size(); ++t) tets[t] = {{m.tets[t][0], m.tets[t][1], m.tets[t][2], m.tets[t][3]}};
  tris_buf_ = upload(ctx, tris);
  tets_buf_ = upload(ctx, tets);
  std::vector<float> mass(nodes_, 0.f);
  for (int64_t n = 0; n < nodes_ && !m.mass_kg.empty(); ++n) mass[n] = float(m.mass_kg[n]);
  mass_ = upload(ctx, mass);
  rest_x_ = upload(ctx, to_float4(m.rest_m));
  rest_m_ = m.rest_m;
  x_ = upload(ctx, std::vector<cl_float4>(nodes_, cl_float4{{0, 0, 0, 0}}), CL_MEM_READ_WRITE);
  v_ = upload(ctx, std::vector<cl_float4>(nodes_, cl_float4{{0, 0, 0, 0}}), CL_MEM_READ_WRITE);
  f_ = cl::Buffer(ctx.context(), CL_MEM_READ_WRITE, std::max<std::size_t>(nodes_, 1) * sizeof(cl_float4));
  tri_force_ = cl::Buffer(ctx.context(), CL_MEM_READ_WRITE, std::max<std::size_t>(tris_, 1) * sizeof(cl_float4));
  tet_force_ = cl::Buffer(ctx.context(), CL_MEM_READ_WRITE, std::max<std::size_t>(4 * tets_, 1) * sizeof(cl_float4));
  // Zero the element forces once: a term that is switched off then adds exact zeros.
  ctx.queue().enqueueFillBuffer(tri_force_, cl_float4{{0, 0, 0, 0}}, 0, std::max<std::size_t>(tris_, 1) * sizeof(cl_float4));
  ctx.queue().enqueueFillBuffer(tet_force_, cl_float4{{0, 0, 0, 0}}, 0,
                                std::max<std::size_t>(4 * tets_, 1) * sizeof(cl_float4));

  k_tri_ = ctx.kernel("msd_forces.cl", "triangle_pressure");
  k_tet_ = ctx.kernel("msd_forces.cl", "tet_volume");
  k_node_ = ctx.kernel("msd_forces.cl", "node_forces");
}

void ClForceEvaluator::upload_state(const std::vector<Vec3>& x, const std::vector<Vec3>& v) {
  auto& q = ctx_.queue();
  std::vector<Vec3> u(nodes_);
  for (int64_t n = 0; n < nodes_; ++n) u[n] = x[n] - rest_m_[n];   // in double, then rounded
  q.enqueueWriteBuffer(x_, CL_TRUE, 0, nodes_ * sizeof(cl_float4), to_float4(u).data());
  if (!v.empty()) q.enqueueWriteBuffer(v_, CL_TRUE, 0, nodes_ * sizeof(cl_float4), to_float4(v).data());
}

void ClForceEvaluator::evaluate(const ForceModel& model) {
  auto& q = ctx_.queue();
  const bool pressure = model.pressure_pa != 0.0 && tris_ > 0, volume = model.volume_stiffness_pa != 0.0;
  if (pressure) {
    ocl::set_args(k_tri_, x_, rest_x_, tris_buf_, float(model.pressure_pa), cl_int(tris_), tri_force_);
    q.enqueueNDRangeKernel(k_tri_, cl::NullRange, cl::NDRange(global_size(tris_)), cl::NDRange(kLocal));
  }
  if (volume) {
    ocl::set_args(k_tet_, x_, rest_x_, tets_buf_, float(model.volume_stiffness_pa), cl_int(tets_), tet_force_);
    q.enqueueNDRangeKernel(k_tet_, cl::NullRange, cl::NDRange(global_size(tets_)), cl::NDRange(kLocal));
  }
  ocl::set_args(k_node_, x_, v_, mass_, cl_int(nodes_), spring_node_, spring_k_, spring_c_, spring_rest_,
                cl_int(spring_slots_), cl_int(model.spring_model == SpringModel::Linear), cl_int(model.damping),
                tri_force_, node_tri_, cl_int(pressure ? tri_slots_ : 0), tet_force_, node_tet_,
                cl_int(volume ? tet_slots_ : 0),
                cl_float4{{float(model.gravity_m_s2[0]), float(model.gravity_m_s2[1]), float(model.gravity_m_s2[2]), 0.0f}},
                f_);
  q.enqueueNDRangeKernel(k_node_, cl::NullRange, cl::NDRange(global_size(nodes_)), cl::NDRange(kLocal));
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
