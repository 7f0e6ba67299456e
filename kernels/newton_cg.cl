// Newton's linear solve on the device (host/solve/newton_cl.cpp): the vector operations of block-Jacobi
// preconditioned conjugate gradients (host/solve/conjugate_gradients.cpp is the reference) and the
// parts of the operator the finite elements' product (fem_forces.cl) does not hold: the gas pressure's
// stiffness (pressure_stiffness.cpp), the wall–viscera bonds (interface_tie.cpp), the Levenberg–Marquardt
// shift σD and the held axes. Node vectors are float4 (w unused); a 3×3 block is three float4 columns.

inline float3 block_times(__global const float4* restrict b, const int n, const float3 v) {
  return b[3 * n].xyz * v.x + b[3 * n + 1].xyz * v.y + b[3 * n + 2].xyz * v.z;
}

// z = P r, P the inverse diagonal blocks with held rows and columns zeroed (block_jacobi).
__kernel void cg_precondition(__global const float4* restrict r, __global const float4* restrict precond,
                              const int n_nodes, __global float4* restrict z) {
  const int n = get_global_id(0);
  if (n >= n_nodes) return;
  z[n] = (float4)(block_times(precond, n, r[n].xyz), 0.0f);
}

// d += α p, r −= α Ap.
__kernel void cg_update(__global float4* restrict d, __global float4* restrict r, __global const float4* restrict p,
                        __global const float4* restrict ap, const float alpha, const int n_nodes) {
  const int n = get_global_id(0);
  if (n >= n_nodes) return;
  d[n].xyz += alpha * p[n].xyz;
  r[n].xyz -= alpha * ap[n].xyz;
}

// p = z + β p.
__kernel void cg_direction(__global float4* restrict p, __global const float4* restrict z, const float beta,
                           const int n_nodes) {
  const int n = get_global_id(0);
  if (n >= n_nodes) return;
  p[n].xyz = z[n].xyz + beta * p[n].xyz;
}

// Partial sums of Σ a_n · b_n: each work item strides over the nodes, each work-group sums its items;
// the host adds the groups' sums in double. Launched with a fixed number of groups.
__kernel void cg_dot(__global const float4* restrict a, __global const float4* restrict b, const int n_nodes,
                     __global float* restrict partial) {
  __local float sums[PNEUMO_WORK_GROUP];
  const int lid = get_local_id(0);
  float s = 0.0f;
  for (int n = get_global_id(0); n < n_nodes; n += get_global_size(0)) s += dot(a[n].xyz, b[n].xyz);
  sums[lid] = s;
  barrier(CLK_LOCAL_MEM_FENCE);
  for (int width = PNEUMO_WORK_GROUP / 2; width > 0; width /= 2) {
    if (lid < width) sums[lid] += sums[lid + width];
    barrier(CLK_LOCAL_MEM_FENCE);
  }
  if (lid == 0) partial[get_group_id(0)] = sums[0];
}

// The pressure's stiffness per load (pressure_stiffness.h): y_i += Σ_j u_ij × p_j over the load's
// tetrahedron, u_ji = −u_ij, the six pairs (0,1) (0,2) (0,3) (1,2) (1,3) (2,3) at u[6l … 6l + 5]; each
// load's four contributions go to out[4l + i], gathered per node by cg_gather_loads.
__kernel void cg_pressure_product(__global const float4* restrict p, __global const int4* restrict load_nodes,
                                  __global const float4* restrict u, const int n_loads,
                                  __global float4* restrict out) {
  const int l = get_global_id(0);
  if (l >= n_loads) return;
  const int4 q = load_nodes[l];
  const float3 p0 = p[q.x].xyz, p1 = p[q.y].xyz, p2 = p[q.z].xyz, p3 = p[q.w].xyz;
  const float3 u01 = u[6 * l].xyz, u02 = u[6 * l + 1].xyz, u03 = u[6 * l + 2].xyz;
  const float3 u12 = u[6 * l + 3].xyz, u13 = u[6 * l + 4].xyz, u23 = u[6 * l + 5].xyz;
  out[4 * l] = (float4)(cross(u01, p1) + cross(u02, p2) + cross(u03, p3), 0.0f);
  out[4 * l + 1] = (float4)(-cross(u01, p0) + cross(u12, p2) + cross(u13, p3), 0.0f);
  out[4 * l + 2] = (float4)(-cross(u02, p0) - cross(u12, p1) + cross(u23, p3), 0.0f);
  out[4 * l + 3] = (float4)(-cross(u03, p0) - cross(u13, p1) - cross(u23, p2), 0.0f);
}

// y_n += Σ its loads' contributions (the load adjacency of fem_forces.cl's fem_gather: item = 8 load + vertex).
__kernel void cg_gather_loads(__global const float4* restrict load_out, __global const long* restrict load_start,
                              __global const int* restrict load_item, const int n_nodes, __global float4* restrict y) {
  const int n = get_global_id(0);
  if (n >= n_nodes) return;
  float3 sum = (float3)(0.0f);
  for (long e = load_start[n]; e < load_start[n + 1]; ++e) {
    const int it = load_item[e];
    sum += load_out[4 * (it / 8) + it % 8].xyz;
  }
  y[n].xyz += sum;
}

// The bonds: y_w += k (p_w − p_v), y_v −= k (p_w − p_v). Each node is in one pair at most, so no two
// work items write the same node.
__kernel void cg_tie_product(__global const float4* restrict p, __global const int2* restrict pairs,
                             __global const float* restrict k, const int n_pairs, __global float4* restrict y) {
  const int i = get_global_id(0);
  if (i >= n_pairs) return;
  const int2 q = pairs[i];
  const float3 d = k[i] * (p[q.x].xyz - p[q.y].xyz);
  y[q.x].xyz += d;
  y[q.y].xyz -= d;
}

// y += σ D p (D the diagonal blocks of K), then the held axes of y are zeroed.
__kernel void cg_shift_and_hold(__global float4* restrict y, __global const float4* restrict blocks,
                                __global const float4* restrict p, const float sigma,
                                __global const uchar* restrict hold, const int n_nodes) {
  const int n = get_global_id(0);
  if (n >= n_nodes) return;
  float3 v = y[n].xyz;
  if (sigma > 0.0f) v += sigma * block_times(blocks, n, p[n].xyz);
  const uchar h = hold[n];
  if (h & 1) v.x = 0.0f;
  if (h & 2) v.y = 0.0f;
  if (h & 4) v.z = 0.0f;
  y[n] = (float4)(v, 0.0f);
}
