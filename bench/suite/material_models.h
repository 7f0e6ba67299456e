#pragma once
// The material models side by side (bench_suite.h, "material_models"):
//   lame        Lamé's hollow sphere (method.md §10; ν 0.25 and 0.45) for the springs and each FEM law, at each
//               cube size: the error against the closed form (truth outside the code) and the solve time, on the
//               CPU and, for the finite elements, on every OpenCL device;
//   real_ct     the real CT with the springs' scene and the FEM scene at each preset's cube size: time, Newton
//               iterations or FIRE steps, rise, cavity, inverted tetrahedra;
//   throughput  element updates per second of the FEM forces and stiffness product on each device, against the
//               bytes they move and the triad, beside SofaCUDA's published TetrahedronFEM figure;
//   choice      the model each preset should use by the stated rule, from the rows above.
#include <string>

#include <nlohmann/json.hpp>

#include "suite/bench_context.h"

namespace pneumo::bench {

/// `springs_scene` and `fem_scene` are the real CT's two scenes; the real-CT rows are skipped (with a note) when
/// either is missing, and in a quick run.
nlohmann::json measure_material_models(BenchContext& ctx, const std::string& springs_scene, const std::string& fem_scene);

}  // namespace pneumo::bench
