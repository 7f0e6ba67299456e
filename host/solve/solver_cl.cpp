// The four solvers on an OpenCL device: the same loops as the CPU reference (solve_*.cpp), with the
// state resident on the device and only convergence scalars read back.
#include "solve/solver_cl.h"

#include <cmath>

#include "core/units.h"
#include "solve/forces_cl.h"
#include "solve/solver_common.h"

namespace pneumo {

namespace {

constexpr std::size_t kLocal = ocl::kWorkGroupSize;

using ocl::set_args;

/// What a device solver holds: the force evaluator (positions, velocities, forces), the per-node
/// constants of the integrators, and the reduction buffer.
struct Device {
  Device(ocl::Context& ctx, const Mesh& m, const std::vector<double>& mass)
      : ctx(ctx), m(m), n(cl_int(m.node_count())), eval(with_features(ctx), m, kSolverBytesPerNode),
        global((std::size_t(n) + kLocal - 1) / kLocal * kLocal), groups(global / kLocal), partial_host(groups) {
    std::vector<float> inv(n);
    std::vector<cl_float4> mask(n);
    for (int64_t i = 0; i < n; ++i) {
      inv[i] = mass[i] > 0.0 ? float(1.0 / mass[i]) : 0.0f;
      const uint8_t h = m.hold[i];
      mask[i] = {{h & kHoldX ? 0.f : 1.f, h & kHoldY ? 0.f : 1.f, h & kHoldZ ? 0.f : 1.f, 0.f}};
    }
    inv_mass = buffer(inv);
    hold = buffer(mask);
    partial = cl::Buffer(ctx.context(), CL_MEM_READ_WRITE, groups * sizeof(cl_float4));
    k_monitor = kernel("monitor");
  }
  // Beyond the force evaluator, per node: 1/m, the hold mask, Newmark's five state vectors at most,
  // and a byte for the reduction's partial sums (16 bytes per group of kLocal nodes). The evaluator
  // checks the total against the device before allocating anything.
  static constexpr uint64_t kSolverBytesPerNode = 4 + 16 + 5 * 16 + 1;
  /// Checks the device's features (the reductions need work-groups and local memory).
  static ocl::Context& with_features(ocl::Context& ctx) {
    ocl::require_features(ctx.info(), kLocal, kLocal * sizeof(cl_float4));
    return ctx;
  }
  template <class T>
  cl::Buffer buffer(const std::vector<T>& v) {
    cl::Buffer b(ctx.context(), CL_MEM_READ_WRITE, std::max<std::size_t>(v.size(), 1) * sizeof(T));
    if (!v.empty()) ctx.queue().enqueueWriteBuffer(b, CL_TRUE, 0, v.size() * sizeof(T), v.data());
    return b;
  }
  cl::Buffer zeros4() {
    cl::Buffer b(ctx.context(), CL_MEM_READ_WRITE, std::size_t(n) * sizeof(cl_float4));
    ctx.queue().enqueueFillBuffer(b, cl_float4{{0, 0, 0, 0}}, 0, std::size_t(n) * sizeof(cl_float4));
    return b;
  }
  cl::Kernel kernel(const char* name) { return ctx.kernel("msd_integrators.cl", name); }
  void run(cl::Kernel& k) {
    ctx.queue().enqueueNDRangeKernel(k, cl::NullRange, cl::NDRange(global), cl::NDRange(kLocal));
  }
  /// Runs a reduction kernel and combines its groups in order: component-wise max or sum.
  std::array<double, 4> reduce(cl::Kernel& k, bool sum) {
    run(k);
    ctx.queue().enqueueReadBuffer(partial, CL_TRUE, 0, groups * sizeof(cl_float4), partial_host.data());
    std::array<double, 4> r{0, 0, 0, 0};
    for (const auto& p : partial_host)
      for (int c = 0; c < 4; ++c) {
        const double v = p.s[c];
        r[c] = sum ? r[c] + v : (std::isnan(v) || v > r[c] ? v : r[c]);
      }
    return r;
  }
  struct Observation { double max_free_force, max_speed, max_displacement; };
  Observation observe(cl::Buffer& x, cl::Buffer& v) {
    set_args(k_monitor, eval.forces(), v, x, hold, n, partial);
    const auto r = reduce(k_monitor, false);
    return {r[0], r[1], r[2]};
  }
  std::vector<Vec3> download(cl::Buffer& b) {
    std::vector<cl_float4> raw(n);
    ctx.queue().enqueueReadBuffer(b, CL_TRUE, 0, std::size_t(n) * sizeof(cl_float4), raw.data());
    std::vector<Vec3> out(n);
    for (int64_t i = 0; i < n; ++i) out[i] = Vec3(raw[i].s[0], raw[i].s[1], raw[i].s[2]);
    return out;
  }

  ocl::Context& ctx;
  const Mesh& m;
  cl_int n;
  ClForceEvaluator eval;
  std::size_t global, groups;
  cl::Buffer inv_mass, hold, partial;
  std::vector<cl_float4> partial_host;
  cl::Kernel k_monitor;
};

/// Positions fetched from the device only when the inversion check asks for them.
auto lazy_positions(Device& d, cl::Buffer& x, std::vector<Vec3>& cache) {
  return [&d, &x, &cache]() -> const std::vector<Vec3>& {
    cache = d.eval.download_positions(x);
    return cache;
  };
}

SolveResult explicit_cl(ocl::Context& ctx, const Mesh& m, const SolveOptions& opt, const std::vector<Vec3>& x0) {
  SolveResult r;
  detail::Monitor mon(m, opt, "explicit", r);
  const double dt = detail::chosen_dt(m, opt, opt.forces.damping, r);
  Device d(ctx, m, m.mass_kg);
  d.eval.upload_state(x0, std::vector<Vec3>(x0.size(), Vec3::Zero()));
  cl::Kernel step_k = d.kernel("explicit_step");
  set_args(step_k, d.eval.positions(), d.eval.velocities(), d.eval.forces(), d.inv_mass, d.hold, float(dt), d.n);
  ForceModel model = opt.forces;
  std::vector<Vec3> cache;
  const std::string advice = detail::dt_advice(dt, r.dt_stable_s);
  int64_t step = 0;
  double residual = INFINITY;
  std::optional<StopReason> reason;   // none: go on
  while (step < opt.max_steps) {
    const double t = step * dt;
    model.pressure_pa = detail::ramped_pressure(opt, t);
    d.eval.evaluate(model, ClForceEvaluator::Nodes::Free);
    d.run(step_k);
    ++step;
    if (step % opt.monitor_every != 0 && step != opt.max_steps) continue;
    const auto o = d.observe(d.eval.positions(), d.eval.velocities());
    reason = mon.check_dynamic(step, t + dt, model.pressure_pa, o.max_free_force / mon.reference_load(),
                               o.max_displacement, o.max_speed, advice,
                               lazy_positions(d, d.eval.positions(), cache), &residual);
    if (reason) break;
  }
  r.final_pressure_pa = model.pressure_pa;
  mon.finish(d.eval.download_positions(d.eval.positions()), d.download(d.eval.velocities()), step, step,
             reason.value_or(StopReason::StepLimit), residual);
  return r;
}

SolveResult newmark_cl(ocl::Context& ctx, const Mesh& m, const SolveOptions& opt, const std::vector<Vec3>& x0) {
  SolveResult r;
  detail::Monitor mon(m, opt, "newmark", r);
  const double dt = detail::chosen_dt(m, opt, opt.forces.damping, r);
  const float beta = float(opt.newmark_beta), gamma = float(opt.newmark_gamma);
  const double a_floor = detail::newmark_acceleration_floor(m, mon);
  // float32 cannot resolve a relative change below its noise floor, which depends on how much the
  // forces cancel (typically 1e-6..1e-4 of max |a|): a change that stops falling, or outlasts the
  // iterations, below 1e-3 of max |a| is that floor, not a divergence (a diverging fixed-point
  // iteration grows far past it).
  constexpr double kNoiseFloor = 1e-3;
  Device d(ctx, m, m.mass_kg);
  d.eval.upload_state(x0, {});
  cl::Buffer x = d.zeros4(), v = d.zeros4();
  ctx.queue().enqueueCopyBuffer(d.eval.positions(), x, 0, 0, std::size_t(d.n) * sizeof(cl_float4));
  cl::Buffer a = d.zeros4(), xp = d.zeros4(), vp = d.zeros4();
  cl::Kernel predict = d.kernel("newmark_predict"), trial = d.kernel("newmark_trial"),
             accel = d.kernel("newmark_accel"), commit = d.kernel("newmark_trial");
  set_args(predict, x, v, a, xp, vp, float(dt), beta, gamma, d.n);
  set_args(trial, xp, vp, a, d.hold, d.eval.positions(), d.eval.velocities(), float(dt), beta, gamma, d.n);
  set_args(accel, d.eval.forces(), d.inv_mass, d.hold, a, d.n, d.partial);
  set_args(commit, xp, vp, a, d.hold, x, v, float(dt), beta, gamma, d.n);
  ForceModel model = opt.forces;
  std::vector<Vec3> cache;
  const std::string advice = detail::dt_advice(dt, r.dt_stable_s);
  int64_t step = 0, evaluations = 0;
  double residual = INFINITY;
  std::optional<StopReason> reason;   // none: go on
  while (step < opt.max_steps) {
    const double t_next = (step + 1) * dt;
    model.pressure_pa = detail::ramped_pressure(opt, t_next);
    d.run(predict);
    detail::NewmarkInnerLoop inner(opt.newmark_inner_tolerance, kNoiseFloor);
    for (int k = 0; k < opt.newmark_max_inner; ++k) {
      d.run(trial);
      d.eval.evaluate(model, ClForceEvaluator::Nodes::Free);
      ++evaluations;
      const auto red = d.reduce(accel, false);
      ++r.inner_iterations;
      if (inner.next(red[0], std::max(red[1], a_floor))) break;
    }
    if (inner.failed())
      throw DivergedError(
          detail::newmark_failure(step + 1, inner, opt, dt, r.dt_stable_s),
          r.dt_stable_s);
    d.run(commit);
    ++step;
    if (step % opt.monitor_every != 0 && step != opt.max_steps) continue;
    const auto o = d.observe(x, v);
    reason = mon.check_dynamic(step, t_next, model.pressure_pa, o.max_free_force / mon.reference_load(),
                               o.max_displacement, o.max_speed, advice,
                               lazy_positions(d, x, cache), &residual);
    if (reason) break;
  }
  r.final_pressure_pa = model.pressure_pa;
  mon.finish(d.eval.download_positions(x), d.download(v), step, evaluations,
             reason.value_or(StopReason::StepLimit), residual);
  return r;
}

SolveResult kitasaka_cl(ocl::Context& ctx, const Mesh& m, const SolveOptions& opt, const std::vector<Vec3>& x0) {
  SolveResult r;
  detail::Monitor mon(m, opt, "kitasaka2004", r);
  Device d(ctx, m, detail::stiffness_sums(m));   // inv_mass holds 1/D_i here
  d.eval.upload_state(x0, {});
  cl::Kernel step_k = d.kernel("kitasaka_step");
  set_args(step_k, d.eval.positions(), d.eval.forces(), d.inv_mass, d.hold, float(opt.kitasaka_step), d.n, d.partial);
  ForceModel model = opt.forces;
  model.damping = false;
  std::vector<Vec3> cache;
  int64_t step = 0, evaluations = 0;
  double residual = INFINITY;
  std::optional<StopReason> reason;   // none: go on
  bool forces_are_current = false;   // the monitor just evaluated them at these positions
  while (step < opt.max_steps) {
    if (!forces_are_current) {
      d.eval.evaluate(model, ClForceEvaluator::Nodes::Free);
      ++evaluations;
    }
    forces_are_current = false;
    const double moved = d.reduce(step_k, true)[0];
    ++step;
    const bool done = moved < opt.kitasaka_tolerance_m;
    if (!done && step % opt.monitor_every != 0 && step != opt.max_steps) continue;
    d.eval.evaluate(model, ClForceEvaluator::Nodes::Free);   // forces at the new positions, for the residual
    ++evaluations;
    forces_are_current = true;
    const auto o = d.observe(d.eval.positions(), d.eval.velocities());
    mon.check_diverged(o.max_displacement, step, detail::kKitasakaAdvice);
    residual = o.max_free_force / mon.reference_load();
    if (mon.record(step, 0.0, model.pressure_pa, residual, o.max_displacement, 0.0,
                   lazy_positions(d, d.eval.positions(), cache))) {
      reason = StopReason::InvertedTetrahedra;
      break;
    }
    if (done) { reason = StopReason::Converged; break; }
  }
  r.final_pressure_pa = model.pressure_pa;
  mon.finish(d.eval.download_positions(d.eval.positions()), {}, step, evaluations,
             reason.value_or(StopReason::StepLimit), residual);
  return r;
}

SolveResult static_fire_cl(ocl::Context& ctx, const Mesh& m, const SolveOptions& opt, const std::vector<Vec3>& x0) {
  using F = detail::Fire;
  SolveResult r;
  detail::Monitor mon(m, opt, "static", r);
  Device d(ctx, m, detail::fire_masses(m, opt.forces));
  d.eval.upload_state(x0, std::vector<Vec3>(x0.size(), Vec3::Zero()));
  cl::Buffer &x = d.eval.positions(), &v = d.eval.velocities(), &f = d.eval.forces();
  cl::Kernel mask = d.kernel("mask_forces"), sums = d.kernel("fire_sums"), restart = d.kernel("fire_restart"),
             velocity = d.kernel("fire_velocity"), move = d.kernel("fire_mix_move");
  set_args(mask, f, d.hold, d.n);
  set_args(sums, f, v, d.n, d.partial);
  ForceModel model = opt.forces;
  model.damping = false;
  const int increments = detail::load_increments(opt);
  std::vector<Vec3> cache;
  int64_t step = 0, evaluations = 0;
  double residual = INFINITY;
  std::optional<StopReason> reason;   // none: go on
  auto evaluate = [&] {
    d.eval.evaluate(model, ClForceEvaluator::Nodes::Free);
    d.run(mask);
    ++evaluations;
  };
  for (int inc = 1; inc <= increments && step < opt.max_steps; ++inc) {
    model.pressure_pa = detail::increment_pressure(opt, inc, increments);
    const bool last = inc == increments;
    const double tol = opt.residual_tolerance * (last ? 1.0 : F::kIntermediateToleranceFactor);
    detail::FireControl fire;
    ctx.queue().enqueueFillBuffer(v, cl_float4{{0, 0, 0, 0}}, 0, std::size_t(d.n) * sizeof(cl_float4));
    evaluate();
    bool increment_done = false;
    while (step < opt.max_steps) {
      const double power = d.reduce(sums, true)[0];
      if (fire.after_power(power)) {
        set_args(restart, x, v, float(fire.dt), d.n);
        d.run(restart);
      }
      const double dt = fire.dt, alpha = fire.alpha;
      set_args(velocity, v, f, d.inv_mass, float(dt), d.n);
      d.run(velocity);
      double v_over_f = 0.0;
      if (power > 0.0) {
        const auto s = d.reduce(sums, true);
        if (s[2] > 0.0) v_over_f = std::sqrt(s[1]) / std::sqrt(s[2]);
      }
      set_args(move, x, v, f, float(alpha), float(v_over_f), cl_int(power > 0.0 && v_over_f > 0.0), float(dt), d.n);
      d.run(move);
      evaluate();
      ++step;
      if (step % opt.monitor_every != 0 && step != opt.max_steps) continue;
      const auto o = d.observe(x, v);
      mon.check_diverged(o.max_displacement, step, detail::kLoadAdvice);
      residual = o.max_free_force / mon.reference_load();
      if (mon.record(step, 0.0, model.pressure_pa, residual, o.max_displacement, 0.0, lazy_positions(d, x, cache))) {
        reason = StopReason::InvertedTetrahedra;
        break;
      }
      if (residual < tol) { increment_done = true; break; }
    }
    if (reason) break;
    if (last && increment_done) reason = StopReason::Converged;
    if (!increment_done) break;
  }
  r.final_pressure_pa = model.pressure_pa;
  mon.finish(d.eval.download_positions(x), {}, step, evaluations, reason.value_or(StopReason::StepLimit),
             residual);
  return r;
}

}  // namespace

uint64_t solver_device_bytes(const Mesh& m) { return ClForceEvaluator::device_bytes(m, Device::kSolverBytesPerNode); }

SolveResult solve_opencl(ocl::Context& ctx, const Mesh& m, const SolveOptions& opt, const std::vector<Vec3>& x_start) {
  if (opt.forces.material != MaterialModel::Msd)
    throw std::logic_error("solve_opencl: the device kernels are the springs'; solve through solve_on_device()");
  const std::vector<Vec3>& x0 = x_start.empty() ? m.rest_m : x_start;
  switch (opt.method) {
    case SolverMethod::Explicit: return explicit_cl(ctx, m, opt, x0);
    case SolverMethod::Newmark: return newmark_cl(ctx, m, opt, x0);
    case SolverMethod::Kitasaka2004: return kitasaka_cl(ctx, m, opt, x0);
    case SolverMethod::Static: return static_fire_cl(ctx, m, opt, x0);
    case SolverMethod::Newton:
    case SolverMethod::ImplicitEuler:
      throw std::logic_error(std::string("solve_opencl: ") + enum_name(opt.method) +
                             " has no device implementation of its own; solve through solve_on_device()");
  }
  throw std::logic_error("unknown solver");
}

struct ClExplicitStepper::Impl {
  Impl(ocl::Context& ctx, const Mesh& m, const ForceModel& model, double dt)
      : d(ctx, m, m.mass_kg), model(model), step_k(d.kernel("explicit_step")) {
    set_args(step_k, d.eval.positions(), d.eval.velocities(), d.eval.forces(), d.inv_mass, d.hold, float(dt), d.n);
  }
  Device d;
  ForceModel model;
  cl::Kernel step_k;
};

ClExplicitStepper::ClExplicitStepper(ocl::Context& ctx, const Mesh& m, const ForceModel& model, double dt_s)
    : impl_(std::make_unique<Impl>(ctx, m, model, dt_s)) {}
ClExplicitStepper::~ClExplicitStepper() = default;   // here, where Impl is complete
void ClExplicitStepper::steps(int n) {
  for (int i = 0; i < n; ++i) {
    impl_->d.eval.evaluate(impl_->model, ClForceEvaluator::Nodes::Free);
    impl_->d.run(impl_->step_k);
  }
}
void ClExplicitStepper::finish() { impl_->d.ctx.queue().finish(); }

}  // namespace pneumo
