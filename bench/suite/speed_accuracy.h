#pragma once
// The speed–accuracy trade of the solvers (bench_suite.h, "speed_accuracy"): each solver × cube size L × time step
// or tolerance on one phantom, timed (CPU reference, all threads) and compared with a reference solution (the
// static solver at the finest L and the tightest tolerance) at the same material points (material_points.h):
// RMS and maximum displacement error in mm on the skin and on the cavity surface, and the mean absolute difference
// of the warped CT in HU. Then the Pareto front of time against error and the presets it implies.
#include <nlohmann/json.hpp>

#include "suite/bench_context.h"

namespace pneumo::bench {

nlohmann::json measure_speed_accuracy(BenchContext& ctx);

}  // namespace pneumo::bench
