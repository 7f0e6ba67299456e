// The plain reference of the image warp: warp.h's rules 1–4 as a loop over tetrahedra and the
// voxels of their bounding boxes, one thread, double precision, nothing precomputed. Slow (it
// evaluates every weight of every visited voxel); it exists so that the fast CPU warp (warp_cpu.cpp:
// tiles, cube groups, row spans solved in SSE2) and the kernel (kernels/warp.cl) have something a
// reader can check against warp.h in minutes. Only the tests call it.
#include <algorithm>
#include <cmath>

#include "warp/warp.h"

namespace pneumo {

namespace {

/// The nearest voxel of index point p, or −1 outside the grid (every coordinate in [−½, n − ½)).
int64_t nearest_voxel(const Index3& dims, const Vec3& p) {
  int64_t n[3];
  for (int a = 0; a < 3; ++a) {
    const double q = std::floor(p[a] + 0.5);
    if (!(q >= 0.0 && q < double(dims[a]))) return -1;   // also false for NaN
    n[a] = int64_t(q);
  }
  return n[0] + dims[0] * (n[1] + dims[1] * n[2]);
}

/// Trilinear CT at p, neighbours past the grid's edge clamped to the edge voxel; −1000 HU (air)
/// where the nearest voxel is outside. The products and sums in the order warp_sampling.h uses, so
/// that both give the same bits at the same point.
double ct_trilinear(const Index3& dims, const float* hu, const Vec3& p) {
  if (nearest_voxel(dims, p) < 0) return -1000.0;
  int64_t i0[3], i1[3];
  double f[3];
  for (int a = 0; a < 3; ++a) {
    const double fl = std::floor(p[a]);
    f[a] = p[a] - fl;
    i0[a] = std::clamp<int64_t>(int64_t(fl), 0, dims[a] - 1);
    i1[a] = std::clamp<int64_t>(int64_t(fl) + 1, 0, dims[a] - 1);
  }
  auto at = [&](int64_t i, int64_t j, int64_t k) { return double(hu[i + dims[0] * (j + dims[1] * k)]); };
  const double fx = f[0], fy = f[1], fz = f[2];
  const double c00 = at(i0[0], i0[1], i0[2]) * (1 - fx) + at(i1[0], i0[1], i0[2]) * fx;
  const double c10 = at(i0[0], i1[1], i0[2]) * (1 - fx) + at(i1[0], i1[1], i0[2]) * fx;
  const double c01 = at(i0[0], i0[1], i1[2]) * (1 - fx) + at(i1[0], i0[1], i1[2]) * fx;
  const double c11 = at(i0[0], i1[1], i1[2]) * (1 - fx) + at(i1[0], i1[1], i1[2]) * fx;
  const double c0 = c00 * (1 - fy) + c10 * fy;
  const double c1 = c01 * (1 - fy) + c11 * fy;
  return c0 * (1 - fz) + c1 * fz;
}

}  // namespace

WarpResult warp_reference(const WarpMesh& mesh, const WarpSource& src, const WarpBox& box, const WarpOptions& opt) {
  check_warp_mesh(mesh);
  const Index3 dims = mesh.grid.dims;
  const int64_t nx = box.dims[0], ny = box.dims[1];
  const std::size_t n_out = std::size_t(box.voxel_count());
  WarpResult out;
  out.device = "cpu-reference";
  out.ct_hu.assign(n_out, 0.0f);
  if (src.labels) out.labels.assign(n_out, 0);
  out.outcome.assign(n_out, WarpOutcome::Kept);   // Kept: inside no tetrahedron (yet)

  // Rules 1–3. Tetrahedra in ascending index, so the first to accept a voxel is the lowest.
  for (int64_t t = 0; t < mesh.tet_count(); ++t) {
    if (warp_tet_degenerate(mesh, t)) continue;
    const auto& v = mesh.tets[std::size_t(t)];
    Vec3 x[4], d[4];
    for (int c = 0; c < 4; ++c) x[c] = mesh.deformed_ijk(v[c]), d[c] = mesh.disp_ijk[v[c]];
    Mat3 e, dd;
    e << x[1] - x[0], x[2] - x[0], x[3] - x[0];
    dd << d[1] - d[0], d[2] - d[0], d[3] - d[0];
    const Mat3 e_inv = e.inverse();
    const Part part = mesh.tet_part[std::size_t(t)];
    Index3 lo, hi;   // the deformed tetrahedron's box, one voxel wider, inside the output box
    for (int a = 0; a < 3; ++a) {
      double min_a = x[0][a], max_a = x[0][a];
      for (int c = 1; c < 4; ++c) min_a = std::min(min_a, x[c][a]), max_a = std::max(max_a, x[c][a]);
      lo[a] = std::max<int64_t>(box.lo[a], int64_t(std::floor(min_a)) - 1);
      hi[a] = std::min<int64_t>(box.lo[a] + box.dims[a] - 1, int64_t(std::ceil(max_a)) + 1);
    }
    for (int64_t k = lo[2]; k <= hi[2]; ++k)
      for (int64_t j = lo[1]; j <= hi[1]; ++j)
        for (int64_t i = lo[0]; i <= hi[0]; ++i) {
          const std::size_t n = std::size_t((i - box.lo[0]) + nx * ((j - box.lo[1]) + ny * (k - box.lo[2])));
          if (out.outcome[n] == WarpOutcome::Carried) continue;   // a lower index took it
          const Vec3 p_out(static_cast<double>(i), static_cast<double>(j), static_cast<double>(k));
          const Vec3 w = e_inv * (p_out - x[0]);
          if (1.0 - w.sum() < -kWarpTolerance || w.minCoeff() < -kWarpTolerance) continue;   // rule 1
          const Vec3 p_src = p_out - (d[0] + dd * w);
          const int64_t s = nearest_voxel(dims, p_src);
          const Role role = s < 0 ? Role::Other : src.roles[s];
          const bool accepts = part == Part::Wall ? role != Role::Viscera : role != Role::Wall;   // rule 2
          if (!accepts) {
            out.outcome[n] = WarpOutcome::Gas;   // gas unless a higher index accepts it
            continue;
          }
          out.outcome[n] = WarpOutcome::Carried;   // rule 3
          out.ct_hu[n] = float(ct_trilinear(dims, src.ct_hu, p_src));
          if (src.labels) out.labels[n] = s < 0 ? uint16_t(0) : src.labels[s];
        }
  }

  // Rule 4: what no tetrahedron took is gas inside the meshes' space before (a cube meshed at rest)
  // or after (inside a tetrahedron that refused) deformation, else the voxel's own value.
  for (int64_t k = 0; k < box.dims[2]; ++k)
    for (int64_t j = 0; j < box.dims[1]; ++j)
      for (int64_t i = 0; i < box.dims[0]; ++i) {
        const std::size_t n = std::size_t(i + nx * (j + ny * k));
        const int64_t gi = box.lo[0] + i, gj = box.lo[1] + j, gk = box.lo[2] + k;
        WarpOutcome& what = out.outcome[n];
        if (what == WarpOutcome::Carried) {
          ++out.carried_voxels;
          continue;
        }
        if (what == WarpOutcome::Kept && mesh.in_rest_space(gi, gj, gk)) what = WarpOutcome::Gas;
        if (what == WarpOutcome::Gas) {
          ++out.gas_voxels;
          out.ct_hu[n] = opt.gas_hu;
          if (src.labels) out.labels[n] = opt.cavity_label;
        } else {
          ++out.kept_voxels;
          const int64_t own = mesh.grid.linear_index(gi, gj, gk);
          out.ct_hu[n] = src.ct_hu[own];
          if (src.labels) out.labels[n] = src.labels[own];
        }
      }
  return out;
}

}  // namespace pneumo
