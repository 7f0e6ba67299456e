#include "solve/solve_on_device.h"

#include <atomic>

#include "core/log.h"
#include "solve/contact.h"
#include "solve/fem_force_field_cl.h"
#include "solve/force_field.h"
#include "solve/interface_tie.h"
#include "solve/solver_cl.h"

namespace pneumo {

bool device_implements(const SolveOptions& opt) {
  const bool fem = opt.forces.material != MaterialModel::Msd;
  if (opt.method == SolverMethod::ImplicitEuler) return false;
  // The springs' device schemes have no contact and no interface bond.
  if ((opt.forces.contact_stiffness > 0.0 || opt.forces.tie_interface || opt.forces.tie_attached) && !fem) return false;
  return opt.method == SolverMethod::Newton ? fem : !fem;
}

SolveResult solve_on_device(ocl::Context* ctx, const Mesh& m, const SolveOptions& opt,
                            const std::vector<Vec3>& x_start) {
  if (ctx && device_implements(opt)) {
    if (opt.method != SolverMethod::Newton) return solve_opencl(*ctx, m, opt, x_start);
    const std::unique_ptr<ForceField> field =
        with_interface_tie(m, opt.forces, with_contact(m, opt.forces, make_fem_force_field_cl(*ctx, m, opt.forces.material)));
    return solve_newton_on(m, opt, *field, x_start);
  }
  if (ctx) {
    static std::atomic<bool> said{false};
    if (!said.exchange(true))
      log::info(std::string("solving on the CPU: on OpenCL, newton solves the finite elements and the other "
                            "schemes the springs without contact, not ") +
                enum_name(opt.method) + " with " + enum_name(opt.forces.material) +
                (opt.forces.contact_stiffness > 0.0 ? " and contact" : ""));
  }
  return solve(m, opt, x_start);
}

}  // namespace pneumo
