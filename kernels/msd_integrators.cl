// Integrator updates and the reductions convergence needs (method.md §6), float32, for the
// device solvers in host/solve/solver_cl.cpp. The state is the displacement u = x − x₀ (see
// msd_forces.cl), so "x" below is a displacement and |x| is how far a node moved. Node vectors are float4 (x, y, z, 0); `hold` is a float4
// mask per node, 1 on a free axis and 0 on a held one, so fixed nodes and symmetry planes cost no
// branch. Reductions write one float4 per work-group (a fixed tree, so the same bits every run);
// the host combines the groups in a fixed order.

// PNEUMO_WORK_GROUP: the launch's work-group size, defined by the host (ocl::kWorkGroupSize).
#ifndef PNEUMO_WORK_GROUP
#error "PNEUMO_WORK_GROUP is defined by the host's build options (host/cl/cl_runtime.h)"
#endif

// The work-group's reduction, one fixed tree (the same bits every run): s[0] ends holding the
// element-wise max (max_not_sum) or sum of s[0 .. PNEUMO_WORK_GROUP). Every work-item calls it after
// writing its own s[l].
float4 reduce_group(__local float4* s, const int l, const int max_not_sum) {
  barrier(CLK_LOCAL_MEM_FENCE);
  for (int w = PNEUMO_WORK_GROUP / 2; w > 0; w >>= 1) {
    if (l < w) s[l] = max_not_sum ? fmax(s[l], s[l + w]) : s[l] + s[l + w];
    barrier(CLK_LOCAL_MEM_FENCE);
  }
  return s[0];
}

// v ← (v + Δt·F/m)·hold; x ← x + Δt·v (symplectic Euler).
__kernel void explicit_step(__global float4* restrict x, __global float4* restrict v, __global const float4* restrict f,
                            __global const float* restrict inv_mass, __global const float4* restrict hold,
                            const float dt, const int n) {
  const int i = get_global_id(0);
  if (i >= n) return;
  const float4 vi = (v[i] + dt * inv_mass[i] * f[i]) * hold[i];
  v[i] = vi;
  x[i] += dt * vi;
}

// Per group: max free |F| component, max |v|, max |u| (INFINITY for any non-finite force or displacement).
__kernel void monitor(__global const float4* restrict f, __global const float4* restrict v,
                      __global const float4* restrict x, __global const float4* restrict hold, const int n,
                      __global float4* restrict partial) {
  __local float4 s[PNEUMO_WORK_GROUP];
  const int i = get_global_id(0), l = get_local_id(0);
  float4 m = (float4)(0.0f);
  if (i < n) {
    // Free components only (a held axis reads 0 whatever its force), and INFINITY for a non-finite
    // one: fmax drops NaN, which would let a NaN force pass as a small residual.
    const float4 fh = select((float4)(0.0f), fabs(f[i]), isnotequal(hold[i], (float4)(0.0f)));
    const bool forces_finite = isfinite(fh.x) && isfinite(fh.y) && isfinite(fh.z);
    const float3 d = x[i].xyz;
    const bool finite = isfinite(x[i].x) && isfinite(x[i].y) && isfinite(x[i].z);
    m = (float4)(forces_finite ? fmax(fh.x, fmax(fh.y, fh.z)) : INFINITY, length(v[i].xyz),
                 finite ? length(d) : INFINITY, 0.0f);
  }
  s[l] = m;
  const float4 group = reduce_group(s, l, 1);
  if (l == 0) partial[get_group_id(0)] = group;
}

// F ← F·hold (the static schemes work with the free components only).
__kernel void mask_forces(__global float4* restrict f, __global const float4* restrict hold, const int n) {
  const int i = get_global_id(0);
  if (i < n) f[i] *= hold[i];
}

// Per group: (Σ F·v, Σ |v|², Σ |F|², 0), for FIRE.
__kernel void fire_sums(__global const float4* restrict f, __global const float4* restrict v, const int n,
                        __global float4* restrict partial) {
  __local float4 s[PNEUMO_WORK_GROUP];
  const int i = get_global_id(0), l = get_local_id(0);
  s[l] = i < n ? (float4)(dot(f[i], v[i]), dot(v[i], v[i]), dot(f[i], f[i]), 0.0f) : (float4)(0.0f);
  const float4 group = reduce_group(s, l, 0);
  if (l == 0) partial[get_group_id(0)] = group;
}

// FIRE's restart after uphill motion: x ← x − ½Δt·v, v ← 0.
__kernel void fire_restart(__global float4* restrict x, __global float4* restrict v, const float dt, const int n) {
  const int i = get_global_id(0);
  if (i >= n) return;
  x[i] -= 0.5f * dt * v[i];
  v[i] = (float4)(0.0f);
}

// v ← v + Δt·F/m (F already masked).
__kernel void fire_velocity(__global float4* restrict v, __global const float4* restrict f,
                            __global const float* restrict inv_mass, const float dt, const int n) {
  const int i = get_global_id(0);
  if (i < n) v[i] += dt * inv_mass[i] * f[i];
}

// FIRE's mixing (when mix ≠ 0): v ← (1 − α)v + α·(|v|/|F|)·F; then x ← x + Δt·v.
__kernel void fire_mix_move(__global float4* restrict x, __global float4* restrict v, __global const float4* restrict f,
                            const float alpha, const float v_over_f, const int mix, const float dt, const int n) {
  const int i = get_global_id(0);
  if (i >= n) return;
  float4 vi = v[i];
  if (mix) vi = (1.0f - alpha) * vi + alpha * v_over_f * f[i];
  v[i] = vi;
  x[i] += dt * vi;
}

// Newmark predictor: x̃ = x + Δt v + (½ − β)Δt² a, ṽ = v + (1 − γ)Δt a.
__kernel void newmark_predict(__global const float4* restrict x, __global const float4* restrict v,
                              __global const float4* restrict a, __global float4* restrict xp,
                              __global float4* restrict vp, const float dt, const float beta, const float gamma,
                              const int n) {
  const int i = get_global_id(0);
  if (i >= n) return;
  xp[i] = x[i] + dt * v[i] + (0.5f - beta) * dt * dt * a[i];
  vp[i] = v[i] + (1.0f - gamma) * dt * a[i];
}

// Newmark trial (and commit) state: x = x̃ + βΔt² a, v = (ṽ + γΔt a)·hold.
__kernel void newmark_trial(__global const float4* restrict xp, __global const float4* restrict vp,
                            __global const float4* restrict a, __global const float4* restrict hold,
                            __global float4* restrict x, __global float4* restrict v, const float dt,
                            const float beta, const float gamma, const int n) {
  const int i = get_global_id(0);
  if (i >= n) return;
  x[i] = xp[i] + beta * dt * dt * a[i];
  v[i] = (vp[i] + gamma * dt * a[i]) * hold[i];
}

// a ← F/m·hold; per group: (max |a_new − a_old|, max |a_new|, 0, 0).
__kernel void newmark_accel(__global const float4* restrict f, __global const float* restrict inv_mass,
                            __global const float4* restrict hold, __global float4* restrict a, const int n,
                            __global float4* restrict partial) {
  __local float4 s[PNEUMO_WORK_GROUP];
  const int i = get_global_id(0), l = get_local_id(0);
  float4 m = (float4)(0.0f);
  if (i < n) {
    const float4 an = f[i] * inv_mass[i] * hold[i];
    const float change = length((an - a[i]).xyz);
    m = (float4)(isfinite(change) ? change : INFINITY, length(an.xyz), 0.0f, 0.0f);
    a[i] = an;
  }
  s[l] = m;
  const float4 group = reduce_group(s, l, 1);
  if (l == 0) partial[get_group_id(0)] = group;
}

// The 2004 scheme, all nodes at once (Jacobi): ΔR = Δs·F/D·hold, R ← R + ΔR; per group Σ|ΔR|.
__kernel void kitasaka_step(__global float4* restrict x, __global const float4* restrict f,
                            __global const float* restrict inv_stiffness, __global const float4* restrict hold,
                            const float step, const int n, __global float4* restrict partial) {
  __local float4 s[PNEUMO_WORK_GROUP];
  const int i = get_global_id(0), l = get_local_id(0);
  float moved = 0.0f;
  if (i < n) {
    const float4 d = step * inv_stiffness[i] * f[i] * hold[i];
    x[i] += d;
    moved = length(d.xyz);
  }
  s[l] = (float4)(moved, 0.0f, 0.0f, 0.0f);
  const float4 group = reduce_group(s, l, 0);
  if (l == 0) partial[get_group_id(0)] = group;
}
