// Forces of the mass-spring-damper model (method.md §5) on the device, float32. Equal (within
// float rounding) to host/solve/forces.cpp, the double-precision reference.
//
// State: node displacements u = x − x₀ (not positions). Every difference the forces need is formed
// from rest differences (computed once in double and rounded) plus displacement differences, so the
// float32 rounding scales with the element's size and its deformation, not with the distance from
// the world origin: a spring's error is ~ε·k·h instead of ~ε·k·|x|, ~50× smaller on a CT.
//
// Layout: node vectors are float4 (x, y, z, unused) so every load is one aligned 16-byte access.
// The per-node gather works on blocks of W nodes (W = 8 or 16, a build option), one block per
// work-item, with every quantity a floatW over the block's nodes: the arithmetic (sqrt, divide) is
// explicitly SIMD, which PoCL's implicit vectoriser does not manage for loops with per-node trip
// counts, and on a GPU a block is simply a wider work-item. Blocks group nodes of equal degree (the
// host sorts them), so a block's neighbour records are as many as its nodes' springs, not the
// mesh's largest degree: on the 5-tetrahedron lattice degrees alternate 18 and 6 node by node.
// A record holds slot s of the block's W nodes contiguously: the other ends, k, c, and the rest
// vector x₀_i − x₀_j (x, y, z) and its length. Padding entries have k = c = 0 and point at the
// node itself. Every force is gathered per node in a fixed order: no atomics, the same bits every run.

#ifndef W
#define W 8
#endif
#if W == 8
typedef float8 floatW;
typedef int8 intW;
#define vloadW vload8
#elif W == 16
typedef float16 floatW;
typedef int16 intW;
#define vloadW vload16
#else
#error "W must be 8 or 16"
#endif

// (X, Y, Z)[l] = buf[idx[l]].xyz for the W lanes.
#define GATHER3(buf, idx, X, Y, Z)                 \
  do {                                             \
    _Pragma("unroll") for (int l_ = 0; l_ < W; ++l_) { \
      const float4 t_ = (buf)[((const int*)&(idx))[l_]]; \
      ((float*)&(X))[l_] = t_.x;                   \
      ((float*)&(Y))[l_] = t_.y;                   \
      ((float*)&(Z))[l_] = t_.z;                   \
    }                                              \
  } while (0)

// Gas pressure on the cavity faces embedded in each loaded tetrahedron (host/mesh/mesh.h):
// f_i = −P · cof(D_s) · c_i, cof(D_s)·c = c.x (e2×e3) + c.y (e3×e1) + c.z (e1×e2), 4 vertices.
__kernel void load_pressure(__global const float4* restrict u, __global const float4* restrict rest_x,
                            __global const int4* restrict load_nodes, __global const float4* restrict load_c,
                            const float pressure_pa, const int n_loads, __global float4* restrict load_force) {
  const int t = get_global_id(0);
  if (t >= n_loads) return;
  const int4 q = load_nodes[t];
  const float3 a0 = rest_x[q.x].xyz, ua = u[q.x].xyz;
  const float3 e1 = (rest_x[q.y].xyz - a0) + (u[q.y].xyz - ua);
  const float3 e2 = (rest_x[q.z].xyz - a0) + (u[q.z].xyz - ua);
  const float3 e3 = (rest_x[q.w].xyz - a0) + (u[q.w].xyz - ua);
  const float3 k1 = cross(e2, e3), k2 = cross(e3, e1), k3 = cross(e1, e2);
  _Pragma("unroll") for (int i = 0; i < 4; ++i) {
    const float3 c = load_c[4 * t + i].xyz;
    load_force[4 * t + i] = (float4)(-pressure_pa * (c.x * k1 + c.y * k2 + c.z * k3), 0.0f);
  }
}

// Kitasaka's volume preservation per tetrahedron: f_i = −k_v f_t ((V − V₀)/V₀) ∂V/∂x_i, 4 vertices
// (f_t: the share of the tetrahedron its tissue fills, host/mesh/mesh.h).
// The rest volume is recomputed here from the same rounded rest edges, so an undeformed
// tetrahedron gives exactly zero force.
__kernel void tet_volume(__global const float4* restrict u, __global const float4* restrict rest_x,
                         __global const int4* restrict tets, __global const float* restrict tet_fraction,
                         const float volume_stiffness_pa, const int n_tets, __global float4* restrict tet_force) {
  const int t = get_global_id(0);
  if (t >= n_tets) return;
  const int4 q = tets[t];
  const float3 a0 = rest_x[q.x].xyz, ua = u[q.x].xyz;
  const float3 e1r = rest_x[q.y].xyz - a0, e2r = rest_x[q.z].xyz - a0, e3r = rest_x[q.w].xyz - a0;
  const float3 e1 = e1r + (u[q.y].xyz - ua), e2 = e2r + (u[q.z].xyz - ua), e3 = e3r + (u[q.w].xyz - ua);
  const float3 g1 = cross(e2, e3) / 6.0f;
  const float3 g2 = cross(e3, e1) / 6.0f;
  const float3 g3 = cross(e1, e2) / 6.0f;
  const float3 g0 = -(g1 + g2 + g3);
  const float v0 = dot(e1r, cross(e2r, e3r)) / 6.0f;
  const float volume = dot(e1, g1);
  const float s = -volume_stiffness_pa * tet_fraction[t] * (volume - v0) / v0;
  tet_force[4 * t + 0] = (float4)(s * g0, 0.0f);
  tet_force[4 * t + 1] = (float4)(s * g1, 0.0f);
  tet_force[4 * t + 2] = (float4)(s * g2, 0.0f);
  tet_force[4 * t + 3] = (float4)(s * g3, 0.0f);
}

// The net force on each node of a block: its springs and dampers (nonlinear, or Nimura's linear
// form), plus the pressure-load and tetrahedron forces computed above, plus gravity.
// block_nodes: W node ids per block (−1 pads the last block). *_begin: per block, its first record
// (records of block b: begin[b] … begin[b + 1] − 1). Element records index load_force / tet_force,
// whose last entry is a zero the padding points at.
__kernel void node_forces(__global const float4* restrict u, __global const float4* restrict v,
                          __global const float* restrict mass, const int n_blocks,
                          __global const int* restrict block_nodes,
                          __global const int* restrict spring_begin, __global const int* restrict spring_node,
                          __global const float* restrict spring_k, __global const float* restrict spring_c,
                          __global const float* restrict rest_x, __global const float* restrict rest_y,
                          __global const float* restrict rest_z, __global const float* restrict rest_len,
                          const int linear_springs, const int damping, const float stiffening,
                          __global const float4* restrict load_force, __global const int* restrict load_begin,
                          __global const int* restrict node_load, const int with_loads,
                          __global const float4* restrict tet_force, __global const int* restrict tet_begin,
                          __global const int* restrict node_tet, const int with_tets,
                          const float4 gravity, __global float4* restrict force) {
  const int b = get_global_id(0);
  if (b >= n_blocks) return;
  const intW ids = vloadW(b, block_nodes);
  const intW idl = max(ids, (intW)(0));
  floatW uix, uiy, uiz, vix, viy, viz;
  GATHER3(u, idl, uix, uiy, uiz);
  if (damping) GATHER3(v, idl, vix, viy, viz);
  floatW m;
  _Pragma("unroll") for (int l = 0; l < W; ++l) ((float*)&m)[l] = mass[((const int*)&idl)[l]];
  floatW fx = gravity.x * m, fy = gravity.y * m, fz = gravity.z * m;

  const int s_end = spring_begin[b + 1];
  for (int r = spring_begin[b]; r < s_end; ++r) {
    const intW j = vloadW(r, spring_node);
    const floatW k = vloadW(r, spring_k);
    floatW ujx, ujy, ujz;
    GATHER3(u, j, ujx, ujy, ujz);
    const floatW dux = uix - ujx, duy = uiy - ujy, duz = uiz - ujz;
    floatW dvx = 0.0f, dvy = 0.0f, dvz = 0.0f, c = 0.0f;
    if (damping) {
      floatW vjx, vjy, vjz;
      GATHER3(v, j, vjx, vjy, vjz);
      dvx = vix - vjx;
      dvy = viy - vjy;
      dvz = viz - vjz;
      c = vloadW(r, spring_c);
    }
    if (linear_springs) {   // −k(d − d₀) − c·dv, with d − d₀ = u_i − u_j exactly
      fx -= k * dux + c * dvx;
      fy -= k * duy + c * dvy;
      fz -= k * duz + c * dvz;
    } else {
      const floatW dx = vloadW(r, rest_x) + dux, dy = vloadW(r, rest_y) + duy, dz = vloadW(r, rest_z) + duz;
      const floatW len = sqrt(dx * dx + dy * dy + dz * dz);
      // A zero-length spring has no direction and gives no force (as the CPU reference): e = 0.
      const floatW inv = select((floatW)(0.0f), 1.0f / len, isgreater(len, (floatW)(0.0f)));
      const floatW ex = dx * inv, ey = dy * inv, ez = dz * inv;
      const floatW l0 = vloadW(r, rest_len);
      floatW stretch = len - l0;
      if (stiffening > 0.0f) {   // k·l₀·(e^{bε} − 1)/b in tension (host/solve/forces.h)
        const floatW stiff = l0 * expm1(stiffening * stretch / l0) / stiffening;
        stretch = select(stretch, stiff, isgreater(stretch, (floatW)(0.0f)));
      }
      const floatW s = -k * stretch - c * (dvx * ex + dvy * ey + dvz * ez);
      fx += s * ex;
      fy += s * ey;
      fz += s * ez;
    }
  }
  if (with_loads) {
    const int t_end = load_begin[b + 1];
    for (int r = load_begin[b]; r < t_end; ++r) {
      const intW t = vloadW(r, node_load);   // indexes load_force directly: 4·load + vertex
      floatW gx, gy, gz;
      GATHER3(load_force, t, gx, gy, gz);
      fx += gx;
      fy += gy;
      fz += gz;
    }
  }
  if (with_tets) {
    const int t_end = tet_begin[b + 1];
    for (int r = tet_begin[b]; r < t_end; ++r) {
      const intW t = vloadW(r, node_tet);   // indexes tet_force directly: 4·tet + vertex
      floatW gx, gy, gz;
      GATHER3(tet_force, t, gx, gy, gz);
      fx += gx;
      fy += gy;
      fz += gz;
    }
  }
  _Pragma("unroll") for (int l = 0; l < W; ++l) {
    const int i = ((const int*)&ids)[l];
    if (i >= 0) force[i] = (float4)(((float*)&fx)[l], ((float*)&fy)[l], ((float*)&fz)[l], 0.0f);
  }
}
