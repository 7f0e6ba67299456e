#include "solve/solve_on_device.h"

#include <atomic>

#include "core/error.h"
#include "core/log.h"
#include "solve/contact.h"
#include "solve/fem_force_field_cl.h"
#include "solve/force_field.h"
#include "solve/interface_tie.h"
#include "solve/solver_cl.h"
#include "solve/thorax_beyond_cut.h"

namespace pneumo {

bool device_implements(const SolveOptions& opt) {
  const bool fem = opt.forces.material != MaterialModel::Msd;
  if (opt.method == SolverMethod::ImplicitEuler) return false;
  // The springs' device schemes have no contact and no interface bond.
  if ((opt.forces.contact_stiffness > 0.0 || opt.forces.tie_interface || opt.forces.tie_attached) && !fem) return false;
  return opt.method == SolverMethod::Newton ? fem : !fem;
}

std::string device_shortfall(const SolveOptions& opt, const Mesh* m) {
  if (!device_implements(opt)) {
    const bool ties = opt.forces.tie_interface || opt.forces.tie_attached;
    return std::string("OpenCL solves newton on the finite elements, and the other schemes on the springs without "
                       "contact or bonded interfaces; not ") +
           enum_name(opt.method) + " with " + enum_name(opt.forces.material) +
           (opt.forces.contact_stiffness > 0.0 ? " and contact" : "") +
           (ties ? " and bonded interfaces (mesh.attached_labels)" : "");
  }
  // The springs' device schemes hold no chest beyond a cut (thorax_beyond_cut.h), which only the mesh knows.
  if (m && opt.forces.material == MaterialModel::Msd && !m->thorax_node.empty())
    return "the springs on OpenCL have no chest beyond the CT's cranial cut (material.thorax_compliance_l_per_cmh2o "
           "null slides the cut instead)";
  return "";
}

namespace {
[[noreturn]] void refuse_device(const std::string& device, const std::string& why) {
  throw InputError("device \"" + device + "\" cannot run this solve: " + why +
                   ". Choose device \"cpu\", or set solver.allow_cpu_fallback to solve on the CPU");
}
}  // namespace

void require_device_solves(const std::string& device, const SolveOptions& opt) {
  if (opt.allow_cpu_fallback) return;
  const std::string why = device_shortfall(opt);
  if (!why.empty()) refuse_device(device, why);
}

std::unique_ptr<ForceField> make_device_force_field(ocl::Context& ctx, const Mesh& m, const ForceModel& model) {
  return with_thorax_beyond_cut(
      m, with_interface_tie(m, model, with_contact(m, model, make_fem_force_field_cl(ctx, m, model.material))));
}

SolveResult solve_on_device(ocl::Context* ctx, const Mesh& m, const SolveOptions& opt,
                            const std::vector<Vec3>& x_start) {
  const std::string why = ctx ? device_shortfall(opt, &m) : "";
  if (ctx && why.empty()) {
    SolveResult r;
    if (opt.method != SolverMethod::Newton) {
      r = solve_opencl(*ctx, m, opt, x_start);
    } else {
      const std::unique_ptr<ForceField> field = make_device_force_field(*ctx, m, opt.forces);
      r = solve_newton_on(m, opt, *field, x_start);
    }
    r.device = ctx->info().spec() + " " + ctx->info().name;
    return r;
  }
  std::string fallback;
  if (ctx) {
    if (!opt.allow_cpu_fallback) refuse_device(ctx->info().spec(), why);
    fallback = ctx->info().spec() + ": " + why;
    static std::atomic<bool> said{false};
    if (!said.exchange(true)) log::info("solving on the CPU: " + why);
  }
  SolveResult r = solve(m, opt, x_start);
  r.device = "cpu";
  r.device_fallback = fallback;
  return r;
}

}  // namespace pneumo
