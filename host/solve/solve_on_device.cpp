#include "solve/solve_on_device.h"

#include <atomic>

#include "core/log.h"
#include "solve/solver_cl.h"

namespace pneumo {

bool device_implements(const SolveOptions& opt) {
  return opt.method != SolverMethod::Newton && opt.forces.material == MaterialModel::Msd;
}

SolveResult solve_on_device(ocl::Context* ctx, const Mesh& m, const SolveOptions& opt,
                            const std::vector<Vec3>& x_start) {
  if (ctx && device_implements(opt)) return solve_opencl(*ctx, m, opt, x_start);
  if (ctx) {
    static std::atomic<bool> said{false};
    if (!said.exchange(true))
      log::info(std::string("solving on the CPU: the OpenCL solvers implement the springs' four schemes, not ") +
                (opt.method == SolverMethod::Newton ? "newton" : enum_name(opt.forces.material)));
  }
  return solve(m, opt, x_start);
}

}  // namespace pneumo
