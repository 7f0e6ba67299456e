// Forces of the mass-spring-damper model (method.md §5) on the device, float32. Equal (within
// float rounding) to host/solve/forces.cpp, the double-precision reference.
//
// State: node displacements u = x − x₀ (not positions). Every difference the forces need is formed
// from rest differences (computed once in double and rounded) plus displacement differences, so the
// float32 rounding scales with the element's size and its deformation, not with the distance from
// the world origin: a spring's error is ~ε·k·h instead of ~ε·k·|x|, ~50× smaller on a CT.
//
// Layout: node vectors are float4 (x, y, z, unused) so every load is one aligned 16-byte access.
// Per-node neighbour tables are padded to the mesh's largest degree and stored slot-major
// (table[slot * n_nodes + node]), so neighbouring work-items read neighbouring addresses in every
// slot (coalesced on a GPU, contiguous vectors on PoCL). An entry of −1 ends a node's list.
// Every force is gathered per node in a fixed order: no atomics, the same bits every run.

// Gas pressure on each cavity triangle: F = −P·S·n/3 per vertex, S·n = ½(x_b − x_a)×(x_c − x_a).
__kernel void triangle_pressure(__global const float4* restrict u, __global const float4* restrict rest_x,
                                __global const int4* restrict tris, const float pressure_pa, const int n_tris,
                                __global float4* restrict tri_force) {
  const int t = get_global_id(0);
  if (t >= n_tris) return;
  const int4 q = tris[t];
  const float3 ua = u[q.x].xyz, a0 = rest_x[q.x].xyz;
  const float3 ab = (rest_x[q.y].xyz - a0) + (u[q.y].xyz - ua);
  const float3 ac = (rest_x[q.z].xyz - a0) + (u[q.z].xyz - ua);
  const float3 area_normal = 0.5f * cross(ab, ac);
  tri_force[t] = (float4)(-pressure_pa * area_normal / 3.0f, 0.0f);
}

// Kitasaka's volume preservation per tetrahedron: f_i = −k_v ((V − V₀)/V₀) ∂V/∂x_i, 4 vertices.
// The rest volume is recomputed here from the same rounded rest edges, so an undeformed
// tetrahedron gives exactly zero force.
__kernel void tet_volume(__global const float4* restrict u, __global const float4* restrict rest_x,
                         __global const int4* restrict tets, const float volume_stiffness_pa, const int n_tets,
                         __global float4* restrict tet_force) {
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
  const float s = -volume_stiffness_pa * (volume - v0) / v0;
  tet_force[4 * t + 0] = (float4)(s * g0, 0.0f);
  tet_force[4 * t + 1] = (float4)(s * g1, 0.0f);
  tet_force[4 * t + 2] = (float4)(s * g2, 0.0f);
  tet_force[4 * t + 3] = (float4)(s * g3, 0.0f);
}

// The net force on each node: its springs and dampers (nonlinear, or Nimura's linear form), plus the
// triangle and tetrahedron forces computed above, plus gravity.
// spring_rest holds, per slot, the rest vector x₀_i − x₀_j (xyz) and its length (w).
__kernel void node_forces(__global const float4* restrict u, __global const float4* restrict v,
                          __global const float* restrict mass, const int n_nodes,
                          __global const int* restrict spring_node, __global const float* restrict spring_k,
                          __global const float* restrict spring_c, __global const float4* restrict spring_rest,
                          const int spring_slots, const int linear_springs, const int damping,
                          __global const float4* restrict tri_force, __global const int* restrict node_tri,
                          const int tri_slots,
                          __global const float4* restrict tet_force, __global const int* restrict node_tet,
                          const int tet_slots,
                          const float4 gravity, __global float4* restrict force) {
  const int i = get_global_id(0);
  if (i >= n_nodes) return;
  const float3 ui = u[i].xyz, vi = v[i].xyz;
  float3 f = gravity.xyz * mass[i];
  for (int s = 0; s < spring_slots; ++s) {
    const int e = s * n_nodes + i;
    const int j = spring_node[e];
    if (j < 0) break;
    const float k = spring_k[e];
    const float c = damping ? spring_c[e] : 0.0f;
    const float4 rest = spring_rest[e];
    const float3 du = ui - u[j].xyz;
    const float3 dv = vi - v[j].xyz;
    if (linear_springs) {
      f += -k * du - c * dv;   // −k(d − d₀) with d − d₀ = u_i − u_j exactly
    } else {
      const float3 d = rest.xyz + du;
      const float len = length(d);
      if (len > 0.0f) {
        const float3 dir = d / len;
        f += -k * (len - rest.w) * dir - c * dot(dv, dir) * dir;
      }
    }
  }
  for (int s = 0; s < tri_slots; ++s) {
    const int t = node_tri[s * n_nodes + i];
    if (t < 0) break;
    f += tri_force[t].xyz;
  }
  for (int s = 0; s < tet_slots; ++s) {
    const int t = node_tet[s * n_nodes + i];
    if (t < 0) break;
    f += tet_force[t].xyz;   // t indexes tet_force directly: 4·tet + vertex
  }
  force[i] = (float4)(f, 0.0f);
}
