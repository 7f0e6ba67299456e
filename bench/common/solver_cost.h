#pragma once
// The bytes and floating-point operations one node's force evaluation (and explicit step) must move and compute,
// counted from the data structures: the denominators of the solver's roofline ratios, shared by the Google Benchmark
// binary (bench_solver.cpp) and `pneumo bench`.
//
// Byte counts (every array streamed once per pass; the gathers of neighbours' state are counted as cache hits, since
// neighbours lie within a few lattice planes of the node; an element pass reads each distinct vertex's state once).
// A write counts once, as the triad counts it. They follow kernels/msd_forces.cl and msd_integrators.cl (state as
// displacements u = x − x₀) and host/solve/forces.cpp; change them with the kernels.
//   OpenCL, node_forces:  u, v (float4 each), mass (float), its block's node id (int), force written (float4), and
//                         the block records of the spring table: spring_records_per_node × (index, k, c, rest x, y,
//                         z, length: 4 B each) = 28 B per record. Pressure on: triangle_pressure reads each
//                         triangle's int4 and its vertices' u and x₀ (float4 each) and writes its force (float4),
//                         which node_forces reads back, plus per node its triangle records (4 B each, counted as its
//                         degree + 1). Volume term on: likewise per tetrahedron (int4, vertices' u and x₀, 4 float4
//                         forces written and read) and its records.
//   OpenCL, integrator:   explicit_step reads u, v, force, the hold mask (float4 each) and 1/m (float), writes u
//                         and v: 100 B per node.
//   CPU reference:        double Vec3 (24 B). Per spring: its 2 node ids, k, c, rest length, its force written and
//                         read back by the gather, 2 adjacency entries; per node: x, v, mass, the adjacency row
//                         start, the force written; per triangle: ids, its vertices' x, force written and read, 3
//                         adjacency entries (+ each node's row start). Integrator: reads x, v, f, mass, hold;
//                         writes x, v.
//
// Peak float32 is assumed 115 GFLOP/s per core (platform.md: ~230 GFLOP/s on the 2-core Zen 4 with float8/16
// arithmetic), double half of that; per OpenCL device its compute units × that. PNEUMO_BENCH_PEAK_GFLOP_S overrides
// a device's float32 peak (e.g. for a GPU).
#include "cl/cl_runtime.h"
#include "mesh/mesh.h"
#include "solve/forces.h"

namespace pneumo::bench {

struct Cost {
  double bytes = 0.0, flops = 0.0;   // per node
};

constexpr double kPeakF32PerCore = 115e9;   // platform.md: ~230 GFLOP/s float32 on 2 cores

/// Float32 peak of an OpenCL device (compute units × kPeakF32PerCore, or PNEUMO_BENCH_PEAK_GFLOP_S).
double cl_peak_flop_s(const ocl::DeviceInfo& info);
/// Double-precision peak of the CPU reference on `threads` threads.
inline double cpu_peak_flop_s(int threads) { return 0.5 * kPeakF32PerCore * threads; }

/// One force evaluation on a device. gathered: the share of node blocks node_forces runs on (1, or the blocks with
/// a free node in a solver's step).
Cost cl_force_cost(const Mesh& m, const ForceModel& model, double spring_records_per_node, double gathered);
/// One force evaluation of the CPU reference.
Cost cpu_force_cost(const Mesh& m, const ForceModel& model);
/// One explicit step (force evaluation + integrator).
Cost cl_step_cost(const Mesh& m, const ForceModel& model, double spring_records_per_node, double gathered);
Cost cpu_step_cost(const Mesh& m, const ForceModel& model);

/// Where an achieved rate stands: rate / min(bandwidth / bytes, peak / flops).
struct Roofline {
  double fraction = 0.0;
  bool memory_bound = true;   // which bound binds
  double bound_rate = 0.0;    // the binding bound, in the rate's units
};
Roofline roofline(double rate, const Cost& cost, double bandwidth_gb_s, double peak_flop_s);

}  // namespace pneumo::bench
