// The barycentric image warp (method.md §7) on the device, float32. host/warp/warp.h states the
// rules; host/warp/warp_cpu.cpp is the double-precision CPU warp this must equal (CT within a
// stated tolerance, labels exactly except at measured ties).
//
// Two passes, no order dependence:
//  warp_scatter (one work-item per deformed tetrahedron) visits the voxel centres of its bounding
//    box, tests containment (every barycentric weight ≥ −tol), maps accepted centres back to their
//    source point and checks the role there; it records the lowest accepting tetrahedron's index
//    per voxel with atomic_min (T, one past the last index, marks "inside a deformed tetrahedron
//    but accepted by none"; INT_MAX "inside none"). The lowest index wins whatever the schedule.
//  warp_sample (one work-item per few voxels of a row) recomputes the winner's weights and source point
//    (the same arithmetic, so the same bits) and samples: CT trilinear, label nearest; or gas; or
//    the voxel's own value.
//
// Coordinates are voxel indices of the working grid (centre of voxel (i,j,k) at (i,j,k)).
// Per tetrahedron, 8 float4 (host/warp/warp_cl.cpp prepares them in double and rounds once):
//   [0] deformed vertex 0 (w: part, 0 wall / 1 viscera)   [1..3] rows of the inverse edge matrix
//   [4] displacement of vertex 0                           [5..7] rows of [d1−d0, d2−d0, d3−d0]
// The source point is p − (d0 + D·w): equal displacements cancel exactly, so an identity or a
// whole-voxel translation lands on whole voxels and samples them bit for bit.
#pragma OPENCL FP_CONTRACT OFF

#define ROLE_OTHER 0
#define ROLE_WALL 1
#define ROLE_VISCERA 2
#define OUTCOME_KEPT 0
#define OUTCOME_CARRIED 1
#define OUTCOME_GAS 2
#define OUTSIDE_HU -1000.0f

// Nearest voxel's linear index in a grid of `dims`, or −1 outside ([−½, n − ½) on each axis).
long nearest_voxel(const float3 p, const int4 dims) {
  const float3 f = floor(p + 0.5f);
  if (!(f.x >= 0.0f && f.x < (float)dims.x && f.y >= 0.0f && f.y < (float)dims.y && f.z >= 0.0f &&
        f.z < (float)dims.z))
    return -1;
  return (long)f.x + (long)dims.x * ((long)f.y + (long)dims.y * (long)f.z);
}

// Barycentric weights 1..3 of p in tetrahedron t (weight 0 is 1 − their sum).
float3 weights(__global const float4* restrict tet, const long t, const float3 p) {
  const float3 q = p - tet[8 * t].xyz;
  return (float3)(dot(tet[8 * t + 1].xyz, q), dot(tet[8 * t + 2].xyz, q), dot(tet[8 * t + 3].xyz, q));
}

float3 source_point(__global const float4* restrict tet, const long t, const float3 p, const float3 w) {
  const float3 d = tet[8 * t + 4].xyz +
                   (float3)(dot(tet[8 * t + 5].xyz, w), dot(tet[8 * t + 6].xyz, w), dot(tet[8 * t + 7].xyz, w));
  return p - d;
}

bool inside(const float3 w, const float tol) {
  const float w0 = 1.0f - w.x - w.y - w.z;
  return w0 >= -tol && w.x >= -tol && w.y >= -tol && w.z >= -tol;
}

// The voxels of a row worth testing: where each weight, linear along i, is ≥ −tol, widened by one
// voxel each side so that rounding here never drops a voxel the exact test would take. Returns
// (first, last) offsets from lo_x; first > last when empty.
int2 row_span(__global const float4* restrict tet, const long t, const float3 p_lo, const int last, const float tol) {
  const float3 a = weights(tet, t, p_lo);
  const float3 b = (float3)(tet[8 * t + 1].x, tet[8 * t + 2].x, tet[8 * t + 3].x);
  const float ac[4] = {1.0f - a.x - a.y - a.z, a.x, a.y, a.z};
  const float bc[4] = {-b.x - b.y - b.z, b.x, b.y, b.z};
  float t_lo = 0.0f, t_hi = (float)last;
  for (int c = 0; c < 4; ++c) {
    const float bound = (-tol - ac[c]) / bc[c];
    if (bc[c] > 0.0f) t_lo = fmax(t_lo, bound);
    else if (bc[c] < 0.0f) t_hi = fmin(t_hi, bound);
    else if (ac[c] < -tol) t_hi = -1.0f;
  }
  if (!(t_lo <= t_hi + 2.0f)) return (int2)(1, 0);
  t_lo = clamp(t_lo, 0.0f, (float)last);
  t_hi = clamp(t_hi, 0.0f, (float)last);
  return (int2)(max(0, (int)ceil(t_lo) - 1), min(last, (int)floor(t_hi) + 1));
}

__kernel void warp_scatter(__global const float4* restrict tet, __global const int4* restrict bbox, const int n_tets,
                           __global const uchar* restrict roles, const int4 src_dims, const int4 box_lo,
                           const int4 box_dims, const float tol, __global volatile int* owner) {
  const int t = get_global_id(0);
  if (t >= n_tets) return;
  const int4 lo = bbox[2 * t], hi = bbox[2 * t + 1];
  const int part = (int)tet[8 * t].w;
  for (int k = lo.z; k <= hi.z; ++k)
    for (int j = lo.y; j <= hi.y; ++j) {
      const long row = (long)box_dims.x * ((long)(j - box_lo.y) + (long)box_dims.y * (long)(k - box_lo.z)) - box_lo.x;
      const int2 span = row_span(tet, t, (float3)((float)lo.x, (float)j, (float)k), hi.x - lo.x, tol);
      for (int i = lo.x + span.x; i <= lo.x + span.y; ++i) {
        const float3 p = (float3)((float)i, (float)j, (float)k);
        const float3 w = weights(tet, t, p);
        if (!inside(w, tol)) continue;
        const long n = row + i;
        if (owner[n] <= t) continue;   // values only decrease: a lower index is already there
        const long v = nearest_voxel(source_point(tet, t, p, w), src_dims);
        const int role = v < 0 ? ROLE_OTHER : roles[v];
        const bool accept = part == 0 ? role != ROLE_VISCERA : role != ROLE_WALL;
        atomic_min(&owner[n], accept ? t : n_tets);
      }
    }
}

float ct_at(__global const float* restrict ct, const int4 d, const int i, const int j, const int k) {
  return ct[(long)i + (long)d.x * ((long)j + (long)d.y * (long)k)];
}

// Trilinear, the edge voxel standing in for a missing neighbour; air outside (see nearest_voxel).
float ct_trilinear(__global const float* restrict ct, const int4 d, const float3 p) {
  if (nearest_voxel(p, d) < 0) return OUTSIDE_HU;
  const float3 fl = floor(p);
  const float3 f = p - fl;
  const int i = (int)fl.x, j = (int)fl.y, k = (int)fl.z;
  const int i0 = clamp(i, 0, d.x - 1), i1 = clamp(i + 1, 0, d.x - 1);
  const int j0 = clamp(j, 0, d.y - 1), j1 = clamp(j + 1, 0, d.y - 1);
  const int k0 = clamp(k, 0, d.z - 1), k1 = clamp(k + 1, 0, d.z - 1);
  const float c00 = ct_at(ct, d, i0, j0, k0) * (1.0f - f.x) + ct_at(ct, d, i1, j0, k0) * f.x;
  const float c10 = ct_at(ct, d, i0, j1, k0) * (1.0f - f.x) + ct_at(ct, d, i1, j1, k0) * f.x;
  const float c01 = ct_at(ct, d, i0, j0, k1) * (1.0f - f.x) + ct_at(ct, d, i1, j0, k1) * f.x;
  const float c11 = ct_at(ct, d, i0, j1, k1) * (1.0f - f.x) + ct_at(ct, d, i1, j1, k1) * f.x;
  const float c0 = c00 * (1.0f - f.y) + c10 * f.y;
  const float c1 = c01 * (1.0f - f.y) + c11 * f.y;
  return c0 * (1.0f - f.z) + c1 * f.z;
}

// One work-item per `row_chunk` consecutive output voxels of a row. A CPU device wants long chunks
// (one work-item per voxel makes millions of tiny work-groups, whose launch costs more than their
// work); a GPU wants 1, so that neighbouring work-items read and write neighbouring voxels and its
// memory accesses coalesce. Global size: the row count × ceil(box_dims.x / row_chunk), rounded up
// to the local size.
__kernel void warp_sample(__global const float4* restrict tet, __global const int* restrict owner, const int n_tets,
                          __global const float* restrict ct, __global const ushort* restrict labels,
                          const int has_labels, const int4 src_dims, const int4 box_lo, const int4 box_dims,
                          __global const uchar* restrict cube_meshed, const int4 cubes,
                          __global const int* restrict cube_of, const float gas_hu, const ushort cavity_label,
                          const int row_chunk, __global float* restrict out_ct, __global ushort* restrict out_labels,
                          __global uchar* restrict out_outcome) {
  const long gid = get_global_id(0);
  const int chunks = (box_dims.x + row_chunk - 1) / row_chunk;
  const long row = gid / chunks;
  if (row >= (long)box_dims.y * (long)box_dims.z) return;
  const int y = (int)(row % box_dims.y), z = (int)(row / box_dims.y);
  const int x_begin = (int)(gid % chunks) * row_chunk, x_end = min(box_dims.x, x_begin + row_chunk);
  const int j = y + box_lo.y, k = z + box_lo.z;
  // cube_of: the lattice cube of each index, axis after axis (a table: no divisions per voxel).
  const long cube_row = (long)cubes.x * ((long)cube_of[src_dims.x + j] + (long)cubes.y * (long)cube_of[src_dims.x + src_dims.y + k]);
  const long src_row = (long)src_dims.x * ((long)j + (long)src_dims.y * (long)k);
  for (int x = x_begin; x < x_end; ++x) {
    const long n = (long)x + (long)box_dims.x * row;
    const int i = x + box_lo.x;
    const int o = owner[n];
    float hu;
    ushort label = 0;
    uchar outcome;
    if (o < n_tets) {
      const float3 p = (float3)((float)i, (float)j, (float)k);
      const float3 src = source_point(tet, o, p, weights(tet, o, p));
      hu = ct_trilinear(ct, src_dims, src);
      if (has_labels) {
        const long v = nearest_voxel(src, src_dims);
        label = v < 0 ? (ushort)0 : labels[v];
      }
      outcome = OUTCOME_CARRIED;
    } else if (o == n_tets || cube_meshed[cube_row + cube_of[i]] != 0) {
      hu = gas_hu;
      label = cavity_label;
      outcome = OUTCOME_GAS;
    } else {
      hu = ct[src_row + i];
      if (has_labels) label = labels[src_row + i];
      outcome = OUTCOME_KEPT;
    }
    out_ct[n] = hu;
    if (has_labels) out_labels[n] = label;
    out_outcome[n] = outcome;
  }
}
