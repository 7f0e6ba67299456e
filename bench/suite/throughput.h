#pragma once
// Stage throughput of one case on every device (bench_suite.h, "throughput").
#include <nlohmann/json.hpp>

#include "suite/bench_cases.h"
#include "suite/bench_context.h"

namespace pneumo::bench {

/// Per device: force evaluations and explicit steps (force_evals_per_s, node_updates_per_s, roofline against the
/// triad of the same device), then `pipeline_reps` passes of solve (the scene's solver) → warp → one rendered
/// frame (seconds of each, the warp's voxels_per_s and roofline, end-to-end seconds with the case's roles and mesh
/// time); then the renderer alone (frames_per_s: GL, and the CPU reference at a reduced size).
nlohmann::json measure_case_throughput(BenchContext& ctx, const BenchCase& c, int pipeline_reps);

}  // namespace pneumo::bench
