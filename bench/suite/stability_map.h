#pragma once
// The stability map (bench_suite.h, "stability"): for explicit integration and Newmark-β, the largest Δt that
// stays stable, found by bisection, against method.md §6's estimate (stable_time_step: Gershgorin's bound on
// ω_max with each node's damping), across Young's modulus E and cube size L.
#include <nlohmann/json.hpp>

#include "suite/bench_context.h"

namespace pneumo::bench {

nlohmann::json measure_stability_map(BenchContext& ctx);

}  // namespace pneumo::bench
