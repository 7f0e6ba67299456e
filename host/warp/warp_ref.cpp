// The CPU reference of the image warp (warp.h states the rules; method.md §7). Double precision,
// written apart from the kernel (kernels/warp.cl) so the equality test is not blind to shared bugs.
//
// Scatter without atomics: the output is cut into slabs of a few k-planes; each tetrahedron is
// listed, in index order, under every slab its bounding box touches. One thread owns a slab at a
// time and visits its tetrahedra in ascending order, so "the lowest accepting index wins" is "the
// first accepting one wins", whatever the thread count. Each slab records, per voxel, the winning
// tetrahedron and its source point, then samples the CT and labels there.
#include <omp.h>

#include <algorithm>
#include <atomic>
#include <cmath>

#include "core/progress.h"
#include "warp/phase_timer.h"
#include "warp/warp.h"
#include "warp/warp_sampling.h"

namespace pneumo {

namespace {

constexpr int64_t kSlabPlanes = 2;

/// One deformed tetrahedron, ready for containment tests.
struct RefTet {
  bool skip = true;                // degenerate (warp_tet_degenerate)
  Vec3 x0;                         // deformed vertex 0
  Mat3 e_inv;                      // inverse of [x1−x0, x2−x0, x3−x0]
  Vec3 d0;                         // displacement of vertex 0
  Mat3 dd;                         // [d1−d0, d2−d0, d3−d0]
  Index3 lo{0, 0, 0}, hi{-1, -1, -1};   // voxel centres of the bounding box (box-clipped, inclusive)
  Part part = Part::Wall;
};

RefTet prepare(const WarpMesh& m, int64_t t, const WarpBox& box) {
  RefTet r;
  if (warp_tet_degenerate(m, t)) return r;
  const auto& v = m.tets[std::size_t(t)];
  Vec3 x[4];
  for (int c = 0; c < 4; ++c) x[c] = m.deformed_ijk(v[c]);
  Mat3 e;
  e << x[1] - x[0], x[2] - x[0], x[3] - x[0];
  r.x0 = x[0];
  r.e_inv = e.inverse();
  r.d0 = m.disp_ijk[v[0]];
  r.dd << m.disp_ijk[v[1]] - r.d0, m.disp_ijk[v[2]] - r.d0, m.disp_ijk[v[3]] - r.d0;
  r.part = m.tet_part[std::size_t(t)];
  r.skip = false;
  for (int a = 0; a < 3; ++a) {
    double lo = x[0][a], hi = x[0][a];
    for (int c = 1; c < 4; ++c) lo = std::min(lo, x[c][a]), hi = std::max(hi, x[c][a]);
    // Weights ≥ −ε reach at most 3ε of the extent beyond the box; 4ε leaves room.
    const double margin = 4.0 * kWarpTolerance * (hi - lo) + 1e-9;
    r.lo[a] = std::max<int64_t>(box.lo[a], int64_t(std::ceil(lo - margin)));
    r.hi[a] = std::min<int64_t>(box.lo[a] + box.dims[a] - 1, int64_t(std::floor(hi + margin)));
    if (r.lo[a] > r.hi[a]) r.skip = true;
  }
  return r;
}

/// The voxels of row (j, k) worth testing: where each barycentric weight, linear along the row, is
/// ≥ −tolerance, widened by one voxel on each side so rounding in this estimate never drops a voxel
/// the exact per-voxel test would take. Empty when first > last.
std::pair<int64_t, int64_t> row_span(const RefTet& r, int64_t j, int64_t k) {
  const Vec3 a = r.e_inv * (Vec3(double(r.lo[0]), double(j), double(k)) - r.x0);   // weights 1..3 at i = lo
  const Vec3 b = r.e_inv.col(0);                                                   // their change per voxel
  const double last = double(r.hi[0] - r.lo[0]);
  double t_lo = 0.0, t_hi = last;
  auto clip = [&](double ac, double bc) {   // ac + bc·t ≥ −tolerance
    const double bound = (-kWarpTolerance - ac) / bc;
    if (bc > 0) t_lo = std::max(t_lo, bound);
    else if (bc < 0) t_hi = std::min(t_hi, bound);
    else if (ac < -kWarpTolerance) t_hi = -1.0;
  };
  clip(1.0 - a.sum(), -b.sum());
  for (int c = 0; c < 3; ++c) clip(a[c], b[c]);
  if (!(t_lo <= t_hi + 2.0)) return {1, 0};
  t_lo = std::clamp(t_lo, 0.0, last);
  t_hi = std::clamp(t_hi, 0.0, last);
  return {r.lo[0] + std::max<int64_t>(0, int64_t(std::ceil(t_lo)) - 1),
          r.lo[0] + std::min<int64_t>(r.hi[0] - r.lo[0], int64_t(std::floor(t_hi)) + 1)};
}

/// Whether each cube of row (j, k) was meshed at rest, indexed by cube_of_i[i]; null when the row
/// lies beyond the lattice.
const uint8_t* rest_row(const WarpMesh& m, int64_t j, int64_t k) {
  const int64_t b = j / m.cube_voxels, c = k / m.cube_voxels;
  if (b >= m.cubes[1] || c >= m.cubes[2]) return nullptr;
  return m.cube_meshed.data() + m.cubes[0] * (b + m.cubes[1] * c);
}

}  // namespace

WarpResult warp_ref(const WarpMesh& mesh, const WarpSource& src, const WarpBox& box, const WarpOptions& opt) {
  check_warp_mesh(mesh);
  PhaseTimer timer("warp on cpu");
  const int64_t T = mesh.tet_count();
  std::vector<RefTet> tets(static_cast<std::size_t>(T));
#pragma omp parallel for schedule(static)
  for (int64_t t = 0; t < T; ++t) tets[std::size_t(t)] = prepare(mesh, t, box);

  const int64_t nz = box.dims[2];
  const int64_t slabs = (nz + kSlabPlanes - 1) / kSlabPlanes;
  std::vector<std::vector<int32_t>> by_slab(static_cast<std::size_t>(slabs));
  for (int64_t t = 0; t < T; ++t) {
    const RefTet& r = tets[std::size_t(t)];
    if (r.skip) continue;
    for (int64_t s = (r.lo[2] - box.lo[2]) / kSlabPlanes; s <= (r.hi[2] - box.lo[2]) / kSlabPlanes; ++s)
      by_slab[std::size_t(s)].push_back(int32_t(t));
  }

  timer.lap("prepare");
  const SourceGrid grid{mesh.grid.dims, src.ct_hu, src.labels, src.roles};
  WarpResult out;
  out.device = "cpu";
  const int64_t n_out = box.voxel_count();
  out.ct_hu.resize(std::size_t(n_out));
  if (src.labels) out.labels.resize(std::size_t(n_out));
  out.outcome.resize(std::size_t(n_out));

  const int64_t nx = box.dims[0], ny = box.dims[1], plane = nx * ny;
  // Cube column of each voxel column i (a table: an integer division per voxel costs more than the rest).
  std::vector<int64_t> cube_of_i(std::size_t(mesh.grid.dims[0]));
  for (int64_t i = 0; i < mesh.grid.dims[0]; ++i) cube_of_i[std::size_t(i)] = i / mesh.cube_voxels;
  timer.lap("allocate");
  Progress progress("warp", slabs);
  std::atomic<int64_t> done{0};
#pragma omp parallel
  {
    constexpr int32_t kNone = -1;
    std::vector<int32_t> owner(std::size_t(plane * kSlabPlanes));
    std::vector<uint8_t> covered(owner.size());
    std::vector<Vec3> source(owner.size());
#pragma omp for schedule(dynamic, 1)
    for (int64_t s = 0; s < slabs; ++s) {
      const int64_t k_begin = box.lo[2] + s * kSlabPlanes;
      const int64_t k_end = std::min(k_begin + kSlabPlanes, box.lo[2] + nz);
      std::fill(owner.begin(), owner.end(), kNone);
      std::fill(covered.begin(), covered.end(), 0);
      // 1. Scatter: every tetrahedron over its bounding box inside this slab, ascending index.
      for (int32_t t : by_slab[std::size_t(s)]) {
        const RefTet& r = tets[std::size_t(t)];
        for (int64_t k = std::max(r.lo[2], k_begin); k <= std::min(r.hi[2], k_end - 1); ++k)
          for (int64_t j = r.lo[1]; j <= r.hi[1]; ++j) {
            const auto [i_begin, i_end] = row_span(r, j, k);
            for (int64_t i = i_begin; i <= i_end; ++i) {
              const Vec3 p = Vec3(double(i), double(j), double(k));
              const Vec3 w = r.e_inv * (p - r.x0);
              const double w0 = 1.0 - w[0] - w[1] - w[2];
              if (w0 < -kWarpTolerance || w.minCoeff() < -kWarpTolerance) continue;
              const int64_t n = (i - box.lo[0]) + nx * ((j - box.lo[1]) + ny * (k - k_begin));
              covered[std::size_t(n)] = 1;
              if (owner[std::size_t(n)] != kNone) continue;   // a lower index already accepted it
              const Vec3 from = p - (r.d0 + r.dd * w);
              const Role role = grid.role_nearest(from);
              const bool accept = r.part == Part::Wall ? role != Role::Viscera : role != Role::Wall;
              if (!accept) continue;
              owner[std::size_t(n)] = t;
              source[std::size_t(n)] = from;
            }
          }
      }
      // 2. Sample, or decide gas / unchanged.
      for (int64_t k = k_begin; k < k_end; ++k)
        for (int64_t j = box.lo[1]; j < box.lo[1] + ny; ++j) {
          const uint8_t* meshed_row = rest_row(mesh, j, k);
          for (int64_t i = box.lo[0]; i < box.lo[0] + nx; ++i) {
            const int64_t n = (i - box.lo[0]) + nx * ((j - box.lo[1]) + ny * (k - k_begin));
            const int64_t o = (i - box.lo[0]) + nx * ((j - box.lo[1]) + ny * (k - box.lo[2]));
            WarpOutcome what;
            float hu;
            uint16_t label = 0;
            if (owner[std::size_t(n)] != kNone) {
              what = WarpOutcome::Carried;
              const Vec3& from = source[std::size_t(n)];
              hu = float(grid.ct_trilinear(from));
              if (src.labels) label = grid.label_nearest(from);
            } else if (covered[std::size_t(n)] || (meshed_row && meshed_row[cube_of_i[std::size_t(i)]])) {
              what = WarpOutcome::Gas;
              hu = opt.gas_hu;
              label = opt.cavity_label;
            } else {
              what = WarpOutcome::Kept;
              const int64_t v = mesh.grid.linear_index(i, j, k);
              hu = src.ct_hu[v];
              if (src.labels) label = src.labels[v];
            }
            out.outcome[std::size_t(o)] = what;
            out.ct_hu[std::size_t(o)] = hu;
            if (src.labels) out.labels[std::size_t(o)] = label;
          }
        }
      const int64_t d = ++done;
      if (omp_get_thread_num() == 0) progress.update(d);
    }
  }
  progress.finish();
  timer.lap("scatter and sample");
  for (WarpOutcome w : out.outcome)
    ++(w == WarpOutcome::Carried ? out.carried_voxels : w == WarpOutcome::Gas ? out.gas_voxels : out.kept_voxels);
  timer.lap("count");
  return out;
}

}  // namespace pneumo
