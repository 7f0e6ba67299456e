#include "common/solver_cost.h"

#include <algorithm>
#include <array>
#include <cstdlib>
#include <vector>

#include "mesh/adjacency.h"

namespace pneumo::bench {


namespace {

/// Σ over nodes of (degree + 1): the entries of an element table a node's gather reads (its own and about one of
/// padding).
double table_reads(const Csr& c, int64_t nodes) {
  double r = 0.0;
  for (int64_t n = 0; n < nodes; ++n) r += double(c.end(n) - c.begin(n) + 1);
  return r;
}

/// How many distinct nodes a list of elements touches.
template <std::size_t K>
double distinct_nodes(const std::vector<std::array<int32_t, K>>& elements, int64_t nodes) {
  std::vector<char> seen(std::size_t(nodes), 0);
  for (const auto& e : elements)
    for (const int32_t n : e) seen[std::size_t(n)] = 1;
  return double(std::count(seen.begin(), seen.end(), 1));
}

// FLOPs. OpenCL node_forces, one spring record (nonlinear, damped; padding records compute too): du, dv, d = rest +
// du (9), length (6), reciprocal and direction (4), elastic part (5), damper (9), sum into f (6).
constexpr double kFlopsSpringEndCl = 39;
// CPU reference: one evaluation per spring (d, length, direction, elastic part, damper: 29), then ± gathered at
// both ends (3 each).
constexpr double kFlopsSpringCpu = 29 + 6;
// A pressure load: 3 edges (from rest + displacement on the device), 3 cross products (27), 4 vertices of
// cof(D_s)·c (15 each) and the pressure's scale (12); 4 gathers.
constexpr double kFlopsLoadCl = 18 + 27 + 60 + 12 + 12;
constexpr double kFlopsLoadCpu = 9 + 27 + 60 + 12 + 12;
constexpr double kFlopsTet = 90 + 12;           // 3 edges, 3 cross products, volumes, scale; 4 gathers
constexpr double kFlopsGravity = 3;
constexpr double kFlopsIntegratorCpu = 13;      // dt/m, v += (dt/m) f, x += dt v
constexpr double kFlopsIntegratorCl = 16;       // the same and the hold mask's multiply

constexpr double kClSpringRecordBytes = 7 * 4;                    // index, k, c, rest x, y, z, length
constexpr double kClIntegratorBytes = 3 * 16 + 16 + 4 + 2 * 16;   // u, v, f, hold mask, 1/m; u, v written
constexpr double kCpuIntegratorBytes = 3 * 24 + 8 + 1 + 2 * 24;   // x, v, f, mass, hold; x, v written

/// The nodes of each pressure load's tetrahedron.
std::vector<std::array<int32_t, 4>> load_nodes(const Mesh& m) {
  std::vector<std::array<int32_t, 4>> out(m.load_tet.size());
  for (std::size_t l = 0; l < out.size(); ++l) out[l] = m.tets[m.load_tet[l]];
  return out;
}

}  // namespace

/// gathered: the share of node blocks node_forces runs on (1, or the blocks with a free node in a solver's step).
Cost cl_force_cost(const Mesh& m, const ForceModel& model, double spring_records_per_node, double gathered) {
  const int64_t N = m.node_count();
  const double R = double(m.load_tet.size()), T = double(m.tets.size());
  double bytes = double(N) * (gathered * (16 + 16 + 4 + 4 + 16) + spring_records_per_node * kClSpringRecordBytes);
  double flops = double(N) * (spring_records_per_node * kFlopsSpringEndCl + kFlopsGravity);
  if (model.pressure_pa != 0.0 && R > 0) {
    const Adjacency a = Adjacency::of(m);
    bytes += R * (16 + 4 * 16 + 4 * 16) + 32 * distinct_nodes(load_nodes(m), N) + 4 * table_reads(a.loads, N);
    flops += R * kFlopsLoadCl;
  }
  if (model.volume_stiffness_pa != 0.0 && T > 0) {
    const Adjacency a = Adjacency::of(m);
    bytes += T * (16 + 64 + 64) + 32 * distinct_nodes(m.tets, N) + 4 * table_reads(a.tets, N);
    flops += T * kFlopsTet;
  }
  return Cost{bytes / double(N), flops / double(N)};
}

Cost cpu_force_cost(const Mesh& m, const ForceModel& model) {
  const int64_t N = m.node_count();
  const double S = double(m.springs.size()), R = double(m.load_tet.size()), T = double(m.tets.size());
  double bytes = double(N) * (24 + 24 + 8 + 8 + 24) + S * (8 + 3 * 8 + 24 + 24 + 2 * 4);
  double flops = S * kFlopsSpringCpu + double(N) * kFlopsGravity;
  if (model.pressure_pa != 0.0 && R > 0) {
    bytes += R * (4 + 16 + 4 * 24 + 4 * 24 + 4 * 4) + 24 * distinct_nodes(load_nodes(m), N) + double(N) * 8;
    flops += R * kFlopsLoadCpu;
  }
  if (model.volume_stiffness_pa != 0.0 && T > 0) {
    bytes += T * (16 + 8 + 2 * 96 + 4 * 4) + 24 * distinct_nodes(m.tets, N) + double(N) * 8;
    flops += T * kFlopsTet;
  }
  return Cost{bytes / double(N), flops / double(N)};
}

Cost cl_step_cost(const Mesh& m, const ForceModel& model, double spring_records_per_node, double gathered) {
  Cost c = cl_force_cost(m, model, spring_records_per_node, gathered);
  c.bytes += kClIntegratorBytes;
  c.flops += kFlopsIntegratorCl;
  return c;
}

Cost cpu_step_cost(const Mesh& m, const ForceModel& model) {
  Cost c = cpu_force_cost(m, model);
  c.bytes += kCpuIntegratorBytes;
  c.flops += kFlopsIntegratorCpu;
  return c;
}

double cl_peak_flop_s(const ocl::DeviceInfo& info) {
  if (const char* e = std::getenv("PNEUMO_BENCH_PEAK_GFLOP_S")) return std::atof(e) * 1e9;
  return kPeakF32PerCore * std::max(1u, info.compute_units);
}

Roofline roofline(double rate, const Cost& cost, double bandwidth_gb_s, double peak_flop_s) {
  const double mem_bound = bandwidth_gb_s * 1e9 / cost.bytes;
  const double flop_bound = peak_flop_s / cost.flops;
  Roofline r;
  r.memory_bound = mem_bound <= flop_bound;
  r.bound_rate = std::min(mem_bound, flop_bound);
  r.fraction = rate / r.bound_rate;
  return r;
}

}  // namespace pneumo::bench
