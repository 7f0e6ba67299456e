// The CPU reference of the image warp (warp.h states the rules; method.md §7). Double precision,
// written apart from the kernel (kernels/warp.cl) so the equality test is not blind to shared bugs.
//
// Scatter without atomics: the output is cut into tiles small enough that a tile's output and the
// source it reads stay in a core's L2 cache (a voxel's trilinear stencil and role lookup are
// gathers). Where tetrahedra are small the rows through them are short, and each row's set-up
// (its span, its first source point) costs as much as its voxels: both are kept to a few
// multiply-adds. Each tetrahedron is listed,
// in index order, under every tile its bounding box touches. One thread owns a tile at a time and
// visits its tetrahedra in ascending order, so "the lowest accepting index wins" is "the first
// accepting one wins", whatever the thread count: the first one samples the CT and labels at its
// source point there and then, and later ones leave the voxel alone.
#include <omp.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <exception>
#include <memory>
#include <thread>

#include "core/progress.h"
#include "warp/phase_timer.h"
#include "warp/warp.h"
#include "warp/warp_sampling.h"

namespace pneumo {

namespace {

// Output voxels per tile along i, j, k: 16 K voxels, whose outputs (7 B each) and source stencils
// take a few hundred KiB of a 1–2 MiB L2. Long rows matter most: a tetrahedron cut by a tile's
// i-face costs each of its rows twice, so 256 (on the peers' case a little faster than 64 or 128,
// bench/results/2026-12-01-warp.md); 8 planes match the usual cube size, so a tetrahedron spans two.
constexpr Index3 kTile{256, 8, 8};

/// One deformed tetrahedron, ready for containment tests. No default member values: the table of them
/// (~300 bytes a tetrahedron) is allocated uninitialised and filled in parallel by prepare(), which
/// sets every field, rather than zeroed first on one thread.
struct RefTet {
  bool skip;                        // degenerate (warp_tet_degenerate), or its box misses the output
  Vec3 x0;                          // deformed vertex 0
  Mat3 e_inv;                       // inverse of [x1−x0, x2−x0, x3−x0]
  Vec3 d0;                          // displacement of vertex 0
  Mat3 dd;                          // [d1−d0, d2−d0, d3−d0]
  double w_step[4], w_step_inv[4];  // each weight's change per voxel along i, and its inverse (row spans)
  Index3 lo, hi;                    // voxel centres of the bounding box (box-clipped, inclusive)
  Part part;
  // Every source point it maps lies inside the grid, a whole voxel clear of the far faces: its voxels
  // sample without bounds checks or clamping (SourceGrid's *_interior).
  bool interior;
};

/// A tile's voxel range, inclusive, in working-grid indices.
struct Tile {
  Index3 lo, hi;
};

RefTet prepare(const WarpMesh& m, int64_t t, const WarpBox& box) {
  RefTet r{};
  r.skip = true;
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
  r.w_step[0] = -r.e_inv.col(0).sum();
  for (int c = 0; c < 3; ++c) r.w_step[1 + c] = r.e_inv(c, 0);
  for (int c = 0; c < 4; ++c) r.w_step_inv[c] = 1.0 / r.w_step[c];   // ±inf for 0: row_span looks at the sign first
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
  // Source points are the rest tetrahedron's points at weights ≥ −ε (plus rounding): within its box
  // widened like the deformed one's.
  r.interior = true;
  for (int a = 0; a < 3; ++a) {
    double lo = m.rest_ijk[v[0]][a], hi = lo;
    for (int c = 1; c < 4; ++c) lo = std::min(lo, m.rest_ijk[v[c]][a]), hi = std::max(hi, m.rest_ijk[v[c]][a]);
    const double margin = 4.0 * kWarpTolerance * (hi - lo) + 1e-6;
    r.interior &= lo - margin >= 0.0 && hi + margin < double(m.grid.dims[a] - 1);
  }
  return r;
}

/// The voxels of a row from i_lo to i_hi inside tetrahedron r, given its weights 1..3 at i_lo. Along
/// the row each barycentric weight is affine in i, w_c(i_lo + t) = w_c(i_lo) + t·step_c, so "every
/// weight ≥ −tolerance" is an interval of t bounded by (−tolerance − w_c(i_lo)) / step_c: the
/// containment test solved for the row at once instead of evaluated voxel by voxel. (The two differ
/// only for a voxel whose weight lies within rounding, 1e-15 relative, of −tolerance: a tie by any
/// reckoning.) Empty when first > last.
std::pair<int64_t, int64_t> row_span(const RefTet& r, int64_t i_lo, int64_t i_hi, const Vec3& w_lo) {
  const double w_first[4] = {1.0 - w_lo.sum(), w_lo[0], w_lo[1], w_lo[2]};
  double t_lo = 0.0, t_hi = double(i_hi - i_lo);
  for (int c = 0; c < 4; ++c) {   // w_first + w_step·t ≥ −tolerance
    const double bound = (-kWarpTolerance - w_first[c]) * r.w_step_inv[c];
    if (r.w_step[c] > 0) t_lo = std::max(t_lo, bound);
    else if (r.w_step[c] < 0) t_hi = std::min(t_hi, bound);
    else if (w_first[c] < -kWarpTolerance) t_hi = -1.0;
  }
  if (!(t_lo <= t_hi)) return {1, 0};   // also for NaN
  return {i_lo + ceil_to_int(t_lo), i_lo + floor_to_int(t_hi)};
}

/// Whether each cube of row (j, k) was meshed at rest, indexed by cube_of_i[i]; null when the row
/// lies beyond the lattice.
const uint8_t* rest_row(const WarpMesh& m, int64_t j, int64_t k) {
  const int64_t b = j / m.cube_voxels, c = k / m.cube_voxels;
  if (b >= m.cubes[1] || c >= m.cubes[2]) return nullptr;
  return m.cube_meshed.data() + m.cubes[0] * (b + m.cubes[1] * c);
}

/// The output the scatter writes, its outcome doubling as the scatter's state: Kept = inside no
/// tetrahedron yet, Gas = inside one that refused its source, Carried = taken (and sampled) by the
/// first, so lowest-indexed, accepting one.
struct ScatterOutput {
  WarpOutcome* outcome;
  float* hu;
  uint16_t* label;   // null: no label output
};

/// Voxels row + 0 … row + count of one row inside tetrahedron r, whose source points are
/// source0 + t · step. Interior: r.interior holds, so no source point needs a bounds check.
/// Returns how many voxels it carried.
template <bool Interior>
int64_t scatter_row(const RefTet& r, const SourceGrid& grid, const Vec3& source0, const Vec3& step, int64_t count,
                    std::size_t row, const ScatterOutput& out) {
  int64_t carried = 0;
  for (int64_t t = 0; t <= count; ++t) {
    const std::size_t n = row + std::size_t(t);
    if (out.outcome[n] == WarpOutcome::Carried) continue;   // a lower index already took it
    const Vec3 from = source0 + double(t) * step;
    const int64_t v = Interior ? grid.nearest_interior(from) : grid.nearest(from);
    const Role role = v < 0 ? Role::Other : grid.roles[v];
    if (r.part == Part::Wall ? role == Role::Viscera : role == Role::Wall) {
      out.outcome[n] = WarpOutcome::Gas;   // covered; gas unless a later tetrahedron accepts it
      continue;
    }
    out.outcome[n] = WarpOutcome::Carried;
    if (Interior) out.hu[n] = float(grid.ct_trilinear_interior(from));
    else out.hu[n] = v < 0 ? float(SourceGrid::kOutsideHu) : float(grid.ct_trilinear_inside(from));
    if (out.label) out.label[n] = v < 0 ? uint16_t(0) : grid.labels[v];
    ++carried;
  }
  return carried;
}

}  // namespace

WarpResult warp_ref(const WarpMesh& mesh, const WarpSource& src, const WarpBox& box, const WarpOptions& opt) {
  check_warp_mesh(mesh);
  PhaseTimer timer("warp on cpu");
  const int64_t T = mesh.tet_count();
  // The outputs' hundreds of MB are faulted in and zeroed by the kernel on a thread of their own
  // while the tetrahedra are prepared: each waits on memory, not on the other.
  WarpResult out;
  out.device = "cpu";
  const int64_t n_out = box.voxel_count();
  std::exception_ptr allocate_failed;   // bad_alloc, rethrown here after the join
  std::thread allocate([&] {
    try {
      out.ct_hu.resize(std::size_t(n_out));
      if (src.labels) out.labels.resize(std::size_t(n_out));
      out.outcome.resize(std::size_t(n_out), WarpOutcome::Kept);
    } catch (...) {
      allocate_failed = std::current_exception();
    }
  });
  struct JoinOnExit {   // also when preparing throws: a joinable thread's destructor would terminate
    std::thread& t;
    ~JoinOnExit() {
      if (t.joinable()) t.join();
    }
  } join_allocate{allocate};
  const std::unique_ptr<RefTet[]> tets(new RefTet[std::size_t(T)]);
#pragma omp parallel for schedule(static)
  for (int64_t t = 0; t < T; ++t) tets[std::size_t(t)] = prepare(mesh, t, box);
  timer.lap("tetrahedra");

  Index3 tiles;
  for (int a = 0; a < 3; ++a) tiles[a] = (box.dims[a] + kTile[a] - 1) / kTile[a];
  const int64_t n_tiles = tiles[0] * tiles[1] * tiles[2];
  auto tile_of = [&](int a, int64_t i) { return (i - box.lo[a]) / kTile[a]; };
  std::vector<std::vector<int32_t>> by_tile(static_cast<std::size_t>(n_tiles));
  for (int64_t t = 0; t < T; ++t) {
    const RefTet& r = tets[std::size_t(t)];
    if (r.skip) continue;
    for (int64_t c = tile_of(2, r.lo[2]); c <= tile_of(2, r.hi[2]); ++c)
      for (int64_t b = tile_of(1, r.lo[1]); b <= tile_of(1, r.hi[1]); ++b)
        for (int64_t a = tile_of(0, r.lo[0]); a <= tile_of(0, r.hi[0]); ++a)
          by_tile[std::size_t(a + tiles[0] * (b + tiles[1] * c))].push_back(int32_t(t));
  }

  timer.lap("tiles");
  allocate.join();
  if (allocate_failed) std::rethrow_exception(allocate_failed);
  const SourceGrid grid{mesh.grid.dims, src.ct_hu, src.labels, src.roles};

  const int64_t nx = box.dims[0], ny = box.dims[1];
  // Cube column of each voxel column i (a table: an integer division per voxel costs more than the rest).
  std::vector<int64_t> cube_of_i(std::size_t(mesh.grid.dims[0]));
  for (int64_t i = 0; i < mesh.grid.dims[0]; ++i) cube_of_i[std::size_t(i)] = i / mesh.cube_voxels;
  timer.lap("allocate");
  Progress progress("warp", n_tiles);
  std::atomic<int64_t> done{0};
  int64_t carried = 0, gas = 0, kept = 0;
  // The output voxel of working-grid index (i, j, k).
  auto out_index = [&](int64_t i, int64_t j, int64_t k) {
    return std::size_t((i - box.lo[0]) + nx * ((j - box.lo[1]) + ny * (k - box.lo[2])));
  };
  const ScatterOutput state{out.outcome.data(), out.ct_hu.data(), src.labels ? out.labels.data() : nullptr};
  WarpOutcome* const outcome = state.outcome;
  float* const hu = state.hu;
  uint16_t* const label = state.label;
#pragma omp parallel for schedule(dynamic, 1) reduction(+ : carried, gas, kept)
  for (int64_t n_tile = 0; n_tile < n_tiles; ++n_tile) {
    Tile tile;
    const Index3 at{n_tile % tiles[0], (n_tile / tiles[0]) % tiles[1], n_tile / (tiles[0] * tiles[1])};
    for (int a = 0; a < 3; ++a) {
      tile.lo[a] = box.lo[a] + at[a] * kTile[a];
      tile.hi[a] = std::min(tile.lo[a] + kTile[a], box.lo[a] + box.dims[a]) - 1;
    }
    int64_t tile_carried = 0;
    // 1. Scatter and sample: every tetrahedron over its bounding box inside this tile, ascending
    // index. The weights w and the source point P′ − (d₀ + D w) are affine in the voxel index, so
    // each row starts from its value at the box's corner plus the row's offsets times its steps,
    // and each voxel adds its offset along the row times the step along i. Equal displacements
    // make D zero, so an identity or a whole-voxel translation still lands on whole voxels exactly.
    for (int32_t t : by_tile[std::size_t(n_tile)]) {
      const RefTet& r = tets[std::size_t(t)];
      const Index3 lo{std::max(r.lo[0], tile.lo[0]), std::max(r.lo[1], tile.lo[1]), std::max(r.lo[2], tile.lo[2])};
      const Index3 hi{std::min(r.hi[0], tile.hi[0]), std::min(r.hi[1], tile.hi[1]), std::min(r.hi[2], tile.hi[2])};
      const Vec3 corner(static_cast<double>(lo[0]), static_cast<double>(lo[1]), static_cast<double>(lo[2]));
      const Vec3 w_corner = r.e_inv * (corner - r.x0);
      const Vec3 source_corner = corner - (r.d0 + r.dd * w_corner);
      Vec3 w_along[3], source_along[3];   // per voxel along i, j, k
      for (int a = 0; a < 3; ++a) {
        w_along[a] = r.e_inv.col(a);
        source_along[a] = Vec3::Unit(a) - r.dd * w_along[a];
      }
      for (int64_t k = lo[2]; k <= hi[2]; ++k)
        for (int64_t j = lo[1]; j <= hi[1]; ++j) {
          const double dj = double(j - lo[1]), dk = double(k - lo[2]);
          const Vec3 w_row = w_corner + dj * w_along[1] + dk * w_along[2];
          const auto [first, last] = row_span(r, lo[0], hi[0], w_row);
          if (first > last) continue;
          const double di = double(first - lo[0]);
          const Vec3 source0 = source_corner + di * source_along[0] + dj * source_along[1] + dk * source_along[2];
          const std::size_t row = out_index(first, j, k);
          tile_carried += r.interior ? scatter_row<true>(r, grid, source0, source_along[0], last - first, row, state)
                                     : scatter_row<false>(r, grid, source0, source_along[0], last - first, row, state);
        }
    }
    // 2. What no tetrahedron took: gas inside the meshes' space before or after deformation,
    // otherwise the voxel's own value. Nothing to do in a tile carried whole.
    const int64_t tile_voxels =
        (tile.hi[0] - tile.lo[0] + 1) * (tile.hi[1] - tile.lo[1] + 1) * (tile.hi[2] - tile.lo[2] + 1);
    if (tile_carried == tile_voxels) carried += tile_voxels;
    else for (int64_t k = tile.lo[2]; k <= tile.hi[2]; ++k)
      for (int64_t j = tile.lo[1]; j <= tile.hi[1]; ++j) {
        const uint8_t* meshed_row = rest_row(mesh, j, k);
        const std::size_t row = out_index(tile.lo[0], j, k);
        const int64_t v_row = mesh.grid.linear_index(0, j, k);
        for (int64_t i = tile.lo[0]; i <= tile.hi[0]; ++i) {
          const std::size_t n = row + std::size_t(i - tile.lo[0]);
          WarpOutcome& what = outcome[n];
          if (what == WarpOutcome::Carried) {
            ++carried;
            continue;
          }
          if (what == WarpOutcome::Kept && meshed_row && meshed_row[cube_of_i[std::size_t(i)]]) what = WarpOutcome::Gas;
          if (what == WarpOutcome::Gas) {
            ++gas;
            hu[n] = opt.gas_hu;
            if (label) label[n] = opt.cavity_label;
          } else {
            ++kept;
            hu[n] = src.ct_hu[v_row + i];
            if (label) label[n] = src.labels[v_row + i];
          }
        }
      }
    const int64_t d = ++done;
    if (omp_get_thread_num() == 0) progress.update(d);
  }
  progress.finish();
  out.carried_voxels = carried;
  out.gas_voxels = gas;
  out.kept_voxels = kept;
  timer.lap("scatter and sample");
  return out;
}

}  // namespace pneumo
