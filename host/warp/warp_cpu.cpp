// The fast CPU back end of the image warp (warp.h states the rules; method.md §7). Double precision,
// written apart from the kernel (kernels/warp.cl) so their equality test is not blind to shared
// bugs, and held to the plain reference (warp_reference.cpp) by tests/test_warp_reference.cpp.
//
// Scatter without atomics: the output is cut into tiles small enough that a tile's output and the
// source it reads stay in a core's L2 cache (a voxel's trilinear stencil and role lookup are
// gathers). One thread owns a tile at a time. Where tetrahedra are small the rows through them are
// short (2.5 voxels on average for 8-voxel cubes), and a row's set-up costs as much as its voxels:
// so the tetrahedra of one rest cube go together, their spans along each row through the cube found
// at once (in SSE2, lanes side by side), each voxel going to the lowest-indexed of them that holds
// it. Across groups (shared faces, meshes pressed into each other) a per-voxel owner index keeps
// "the lowest accepting index wins" independent of the order groups come in, whatever the thread
// count; the winner samples the CT and labels at its source point there and then.
#include <omp.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <exception>
#include <memory>
#include <new>
#include <thread>
#include <type_traits>

#include "core/progress.h"
#include "warp/phase_timer.h"
#include "warp/warp.h"
#include "warp/warp_sampling.h"

namespace pneumo {

namespace {

// Output voxels per tile along i, j, k: 16 K voxels, whose outputs (7 B each), owners (4 B) and
// source stencils take a few hundred KiB of a 0.5–2 MiB L2. Long rows matter most: a group cut by a
// tile's i-face costs each of its rows twice, so 256 (on the peers' case a little faster than 64 or
// 128, bench/results/2026-12-01-warp.md); 8 planes match the usual cube size, so a group spans two.
constexpr Index3 kTile{256, 8, 8};

/// One deformed tetrahedron, ready for containment tests. No default member values: the table of them
/// (256 bytes a tetrahedron) is allocated uninitialised and filled in parallel by prepare(), which
/// sets every field, rather than zeroed first on one thread.
struct RefTet {
  bool skip;                        // degenerate (warp_tet_degenerate), or its box misses the output
  Vec3 x0;                          // deformed vertex 0
  Mat3 e_inv;                       // inverse of [x1−x0, x2−x0, x3−x0]
  Vec3 d0;                          // displacement of vertex 0
  Mat3 dd;                          // [d1−d0, d2−d0, d3−d0]
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

/// Whether each cube of row (j, k) was meshed at rest, indexed by cube_of_i[i]; null when the row
/// lies beyond the lattice.
const uint8_t* rest_row(const WarpMesh& m, int64_t j, int64_t k) {
  const int64_t b = j / m.cube_voxels[1], c = k / m.cube_voxels[2];
  if (b >= m.cubes[1] || c >= m.cubes[2]) return nullptr;
  return m.cube_meshed.data() + m.cubes[0] * (b + m.cubes[1] * c);
}

/// What the scatter writes, its outcome doubling as its state: Kept = inside no tetrahedron yet,
/// Gas = inside one that refused its source, Carried = sampled by an accepting one.
struct ScatterOutput {
  WarpOutcome* outcome;
  float* hu;
  uint16_t* label;   // null: no label output
};

/// Per voxel of a tile, the lowest accepting tetrahedron index so far: groups overlap (shared faces,
/// tetrahedra pressed into each other), and comparing indices, not visiting order, makes the lowest
/// accepting index win.
constexpr int32_t kNoOwner = INT32_MAX;

/// Tetrahedra served by one pass along each row: one rest cube's of one part (the five of a lattice
/// cube), ascending index. Rows through a cube are a few voxels long inside each of its tetrahedra
/// but about L long through the cube, so one row set-up replaces five short loops.
constexpr int kMaxGroup = 8;

struct TetGroup {
  int32_t first, count;   // the prepared tetrahedra first .. first + count − 1 (skipped ones among them)
  Index3 lo, hi;          // the union of their bounding boxes
  Part part;
  bool interior;          // every one RefTet::interior
};

/// The order the tetrahedra are prepared and scattered in: by rest cube (the cube holding their rest
/// centroid) and part, ascending index within each, a counting sort. Stored in this order, a group's
/// tetrahedra are adjacent in memory however the mesh numbers them (the peers' mesh numbers its five
/// patterns apart), so a tile reads them as a stream rather than one cache miss each. Any order and
/// grouping give the same result (owners decide); this one gives long rows.
struct CubeOrder {
  std::vector<int32_t> tets;   // tetrahedron indices in cube order
  std::vector<int32_t> start;  // per (cube, part) key, where its tetrahedra begin in `tets`; one more at the end
};

CubeOrder cube_order(const WarpMesh& m) {
  const int64_t T = m.tet_count();
  const Vec3 L(double(std::max(1, m.cube_voxels[0])), double(std::max(1, m.cube_voxels[1])),
               double(std::max(1, m.cube_voxels[2])));
  const int64_t keys = 2 * m.cubes[0] * m.cubes[1] * m.cubes[2];
  std::vector<int64_t> key(static_cast<std::size_t>(T));
#pragma omp parallel for schedule(static)
  for (int64_t t = 0; t < T; ++t) {
    const auto& v = m.tets[std::size_t(t)];
    const Vec3 c = 0.25 * (m.rest_ijk[v[0]] + m.rest_ijk[v[1]] + m.rest_ijk[v[2]] + m.rest_ijk[v[3]]);
    int64_t q = 0;
    for (int a = 2; a >= 0; --a) {   // cube n spans [nL_a − ½, (n+1)L_a − ½); clamped for meshes off the lattice
      const double at = std::clamp(std::floor((c[a] + 0.5) / L[a]), 0.0, double(m.cubes[a] - 1));
      q = q * m.cubes[a] + int64_t(at);
    }
    key[std::size_t(t)] = 2 * q + int64_t(m.tet_part[std::size_t(t)]);
  }
  CubeOrder out;
  out.start.assign(std::size_t(keys + 1), 0);
  for (int64_t k : key) ++out.start[std::size_t(k + 1)];
  for (int64_t k = 0; k < keys; ++k) out.start[std::size_t(k + 1)] += out.start[std::size_t(k)];
  out.tets.resize(std::size_t(T));
  std::vector<int32_t> next(out.start.begin(), out.start.end() - 1);
  for (int64_t t = 0; t < T; ++t) out.tets[std::size_t(next[std::size_t(key[std::size_t(t)])]++)] = int32_t(t);
  return out;
}

/// The groups of up to kMaxGroup adjacent prepared tetrahedra of one (cube, part) key; none where all are
/// skipped.
std::vector<TetGroup> group_tetrahedra(const CubeOrder& order, const RefTet* prepared) {
  std::vector<TetGroup> groups;
  for (std::size_t k = 0; k + 1 < order.start.size(); ++k)
    for (int32_t b = order.start[k]; b < order.start[k + 1]; b += kMaxGroup) {
      TetGroup g;
      g.first = b;
      g.count = std::min(kMaxGroup, order.start[k + 1] - b);
      g.lo = {INT64_MAX, INT64_MAX, INT64_MAX}, g.hi = {INT64_MIN, INT64_MIN, INT64_MIN};
      g.interior = true;
      bool any = false;
      for (int32_t n = b; n < b + g.count; ++n) {
        const RefTet& r = prepared[n];
        if (r.skip) continue;
        any = true;
        g.part = r.part;
        for (int a = 0; a < 3; ++a) g.lo[a] = std::min(g.lo[a], r.lo[a]), g.hi[a] = std::max(g.hi[a], r.hi[a]);
        g.interior &= r.interior;
      }
      if (any) groups.push_back(g);
    }
  return groups;
}

/// A group's tetrahedra along one row: lane g is tetrahedron index[g], covering offsets
/// first[g] .. last[g] from the row's origin, where its source point is src[·][g] + t · step[·][g].
/// A lane covering nothing has first > last.
struct RowLanes {
  alignas(16) int32_t first[kMaxGroup];
  alignas(16) int32_t last[kMaxGroup];
  int32_t index[kMaxGroup];
  double src[3][kMaxGroup], step[3][kMaxGroup];
};

/// One row through a group of `part`: each voxel goes to the lowest-indexed lane covering it whose
/// source role accepts, unless its owner is lower still. Lane by lane in ascending index, each a tight
/// loop over its own span: a voxel a lower lane took is passed over by the owner comparison, one a
/// lower lane refused (gas so far) is still open to the next. `row` and `owner` are the row's origin
/// in the output and in the tile's owners. Interior: every lane's source points lie inside the grid,
/// so none needs a bounds check. Returns how many voxels it carried first.
template <bool Interior>
int64_t scatter_row(const RowLanes& lanes, Part part, const SourceGrid& grid, std::size_t row, int32_t* owner,
                    const ScatterOutput& out) {
  int64_t carried = 0;
  for (int g = 0; g < kMaxGroup; ++g) {
    const int32_t index = lanes.index[g];
    const double src[3] = {lanes.src[0][g], lanes.src[1][g], lanes.src[2][g]};
    const double step[3] = {lanes.step[0][g], lanes.step[1][g], lanes.step[2][g]};
    for (int32_t t = lanes.first[g], last = lanes.last[g]; t <= last; ++t) {
      if (owner[t] < index) continue;   // a lower index took it
      const std::size_t n = row + std::size_t(t);
      const Vec3 from(src[0] + double(t) * step[0], src[1] + double(t) * step[1], src[2] + double(t) * step[2]);
      const int64_t v = Interior ? grid.nearest_interior(from) : grid.nearest(from);
      const Role role = v < 0 ? Role::Other : grid.roles[v];
      if (part == Part::Wall ? role == Role::Viscera : role == Role::Wall) {
        if (owner[t] == kNoOwner) out.outcome[n] = WarpOutcome::Gas;   // gas unless another accepts it
        continue;
      }
      carried += owner[t] == kNoOwner;
      owner[t] = index;
      out.outcome[n] = WarpOutcome::Carried;
      if (Interior) out.hu[n] = float(grid.ct_trilinear_interior(from));
      else out.hu[n] = v < 0 ? float(SourceGrid::kOutsideHu) : float(grid.ct_trilinear_inside(from));
      if (out.label) out.label[n] = v < 0 ? uint16_t(0) : grid.labels[v];
    }
  }
  return carried;
}

/// Where the rows (j, k) of the box a group is scattered over in a tile cross its tetrahedra, all
/// lanes at once (laid out lane-innermost, so each step is one vector operation over the lanes).
/// Along a row each barycentric weight is affine in the offset t from the box's corner,
/// w_c = w_c(row) + t·step_c, so "every weight ≥ −tolerance" is an interval of t: the containment
/// test solved for the row at once instead of evaluated voxel by voxel. Its bounds
/// (−tolerance − w_c(row)) / step_c are themselves affine in the row's offsets (dj, dk): a lower bound
/// where step_c > 0, an upper one where step_c < 0. (This differs from testing voxel by voxel only
/// for a voxel whose weight lies within rounding, 1e-15 relative, of −tolerance: a tie by any
/// reckoning.) The other side's slot holds a bound that never binds, so a row's span takes no
/// branches. A weight constant along i (step_c = 0, faces parallel to i) either holds along the
/// whole row or fails it: its (−tolerance − w_c(row)), scaled by 2^900 (exactly, so its sign is
/// kept), sits among the lower bounds, where any positive value empties the row and any other does
/// nothing. Each plane k adds its part once (plane()); each row then adds dj times the j part (row()).
constexpr double kNeverBinds = 1e300;
constexpr double kConstantScale = 0x1p900;

/// The lanes past a group's last tetrahedron.
const RefTet kEmptyLane = [] {
  RefTet r{};
  r.skip = true;
  return r;
}();

struct GroupSpans {
  // [0]: at the box's corner, [1]: per row along j, [2]: per plane along k; then weight c, then lane.
  alignas(64) double lower[3][4][kMaxGroup];
  alignas(64) double upper[3][4][kMaxGroup];
  alignas(64) double src[3][3][kMaxGroup];   // source point: [0] at the corner, [1] per row, [2] per plane; axis; lane
  // The current plane's: corner + dk · per plane.
  alignas(64) double plane_lower[4][kMaxGroup], plane_upper[4][kMaxGroup], plane_src[3][kMaxGroup];

  /// Lane g from tetrahedron r (a skipped one covers no row), with its source step along i into `lanes`.
  void set_lane(int g, const RefTet& r, const Vec3& corner, RowLanes& lanes) {
    if (r.skip) {
      for (int c = 0; c < 4; ++c) {
        for (int term = 0; term < 3; ++term) lower[term][c][g] = upper[term][c][g] = 0.0;
        lower[0][c][g] = upper[0][c][g] = kNeverBinds;
      }
      for (int term = 0; term < 3; ++term)
        for (int a = 0; a < 3; ++a) src[term][a][g] = 0.0;
      for (int a = 0; a < 3; ++a) lanes.step[a][g] = 0.0;
      return;
    }
    const Vec3 w = r.e_inv * (corner - r.x0);
    const double w_at[4] = {1.0 - w.sum(), w[0], w[1], w[2]};
    const double w_i[4] = {-r.e_inv.col(0).sum(), r.e_inv(0, 0), r.e_inv(1, 0), r.e_inv(2, 0)};
    const double w_j[4] = {-r.e_inv.col(1).sum(), r.e_inv(0, 1), r.e_inv(1, 1), r.e_inv(2, 1)};
    const double w_k[4] = {-r.e_inv.col(2).sum(), r.e_inv(0, 2), r.e_inv(1, 2), r.e_inv(2, 2)};
    for (int c = 0; c < 4; ++c) {
      const double at = -kWarpTolerance - w_at[c];
      const double step = w_i[c];
      double(*bound)[4][kMaxGroup] = step < 0 ? upper : lower;
      double(*other)[4][kMaxGroup] = step < 0 ? lower : upper;
      const double scale = step == 0 ? kConstantScale : 1.0 / step;
      bound[0][c][g] = at * scale, bound[1][c][g] = -w_j[c] * scale, bound[2][c][g] = -w_k[c] * scale;
      other[0][c][g] = step < 0 ? -kNeverBinds : kNeverBinds, other[1][c][g] = 0.0, other[2][c][g] = 0.0;
    }
    const Vec3 at = corner - (r.d0 + r.dd * w);
    const Vec3 per_i = Vec3::Unit(0) - r.dd * r.e_inv.col(0);
    const Vec3 per_j = Vec3::Unit(1) - r.dd * r.e_inv.col(1);
    const Vec3 per_k = Vec3::Unit(2) - r.dd * r.e_inv.col(2);
    for (int a = 0; a < 3; ++a) src[0][a][g] = at[a], src[1][a][g] = per_j[a], src[2][a][g] = per_k[a];
    for (int a = 0; a < 3; ++a) lanes.step[a][g] = per_i[a];
  }

  void plane(double dk) {
    for (int c = 0; c < 4; ++c)
      for (int g = 0; g < kMaxGroup; ++g) {
        plane_lower[c][g] = lower[0][c][g] + dk * lower[2][c][g];
        plane_upper[c][g] = upper[0][c][g] + dk * upper[2][c][g];
      }
    for (int a = 0; a < 3; ++a)
      for (int g = 0; g < kMaxGroup; ++g) plane_src[a][g] = src[0][a][g] + dk * src[2][a][g];
  }

  /// Row dj of the current plane: each lane's offsets clipped to 0 .. t_max (first > last where it
  /// covers none) and its source point at offset 0, into `lanes`. Returns the offsets some lane
  /// covers, first > last when none.
  std::pair<int32_t, int32_t> row(double dj, int32_t t_max, RowLanes& lanes) const {
    // Each lane's span lo .. hi, clipped to −1 .. t_max + 1 so that its truncations stay in int32 and
    // are floor (hi) and, one comparison on, ceil (lo). A NaN bound (none expected: degenerate
    // tetrahedra are skipped) is passed over, as std::max and std::min pass over their second
    // argument's NaN (MAXPD and MINPD return their second operand where either is NaN), so every
    // span stays inside the row.
#if defined(__SSE2__)
    static_assert(kMaxGroup % 2 == 0, "lanes in SSE2 pairs");
    const __m128d at_j = _mm_set1_pd(dj), t_end = _mm_set1_pd(double(t_max)), past_end = _mm_set1_pd(double(t_max) + 1.0),
                  before = _mm_set1_pd(-1.0);
    for (int g = 0; g < kMaxGroup; g += 2) {
      __m128d lo = _mm_setzero_pd(), hi = t_end;
      for (int c = 0; c < 4; ++c) {
        lo = _mm_max_pd(_mm_add_pd(_mm_load_pd(plane_lower[c] + g), _mm_mul_pd(at_j, _mm_load_pd(lower[1][c] + g))), lo);
        hi = _mm_min_pd(_mm_add_pd(_mm_load_pd(plane_upper[c] + g), _mm_mul_pd(at_j, _mm_load_pd(upper[1][c] + g))), hi);
      }
      lo = _mm_min_pd(lo, past_end), hi = _mm_max_pd(hi, before);
      const __m128i lt = _mm_cvttpd_epi32(lo), ht = _mm_cvttpd_epi32(hi);   // two int32 in the low half
      // The comparisons' 64-bit masks (all ones: −1) packed to two int32 beside the truncations.
      auto low_pair = [](__m128d mask) { return _mm_shuffle_epi32(_mm_castpd_si128(mask), _MM_SHUFFLE(2, 0, 2, 0)); };
      const __m128i first = _mm_sub_epi32(lt, low_pair(_mm_cmplt_pd(_mm_cvtepi32_pd(lt), lo)));
      const __m128i last = _mm_add_epi32(ht, low_pair(_mm_cmpgt_pd(_mm_cvtepi32_pd(ht), hi)));
      _mm_storel_epi64(reinterpret_cast<__m128i*>(lanes.first + g), first);
      _mm_storel_epi64(reinterpret_cast<__m128i*>(lanes.last + g), last);
    }
#else
    for (int g = 0; g < kMaxGroup; ++g) {
      double lo = 0.0, hi = double(t_max);
      for (int c = 0; c < 4; ++c) {
        lo = std::max(lo, plane_lower[c][g] + dj * lower[1][c][g]);
        hi = std::min(hi, plane_upper[c][g] + dj * upper[1][c][g]);
      }
      lo = std::min(lo, double(t_max) + 1.0), hi = std::max(hi, -1.0);
      lanes.first[g] = int32_t(ceil_to_int(lo)), lanes.last[g] = int32_t(floor_to_int(hi));
    }
#endif
    int32_t first_all = INT32_MAX, last_all = INT32_MIN;
    for (int g = 0; g < kMaxGroup; ++g) {
      first_all = std::min(first_all, lanes.first[g]);
      last_all = std::max(last_all, lanes.first[g] <= lanes.last[g] ? lanes.last[g] : INT32_MIN);
    }
    for (int a = 0; a < 3; ++a)
      for (int g = 0; g < kMaxGroup; ++g) lanes.src[a][g] = plane_src[a][g] + dj * src[1][a][g];
    return {first_all, last_all};
  }
};

}  // namespace

WarpResult warp_cpu(const WarpMesh& mesh, const WarpSource& src, const WarpBox& box, const WarpOptions& opt) {
  WarpResult out;
  ReusableBuffer scratch;
  warp_cpu(mesh, src, box, opt, out, scratch);
  return out;
}

void warp_cpu(const WarpMesh& mesh, const WarpSource& src, const WarpBox& box, const WarpOptions& opt,
              WarpResult& out, ReusableBuffer& scratch) {
  check_warp_mesh(mesh);
  PhaseTimer timer("warp on cpu");
  const int64_t T = mesh.tet_count();
  out.device = "cpu";
  out.carried_voxels = out.gas_voxels = out.kept_voxels = 0;
  // Outputs of another size are released and allocated anew, faulted in on two threads of their own
  // while the tetrahedra are prepared: the kernel zeroes each page as it is first touched, at a few
  // hundred MB/s a core on a VM, so the HU (4 bytes a voxel) go on one and labels and outcomes (3
  // bytes) on the other. Every voxel is written below (its outcome reset tile by tile), so outputs of
  // this size are reused as they are.
  const std::size_t n_out = std::size_t(box.voxel_count());
  const std::size_t n_labels = src.labels ? n_out : 0;
  const bool allocating = out.ct_hu.size() != n_out || out.labels.size() != n_labels || out.outcome.size() != n_out;
  std::array<std::exception_ptr, 2> allocate_failed;   // bad_alloc, rethrown here after the joins
  std::array<std::thread, 2> allocate;
  if (allocating) {
    // Released before the new ones are allocated (assigning {} would keep the capacity).
    std::vector<float>().swap(out.ct_hu);
    std::vector<uint16_t>().swap(out.labels);
    std::vector<WarpOutcome>().swap(out.outcome);
    auto start = [&](int n, auto resize) {
      allocate[n] = std::thread([&allocate_failed, n, resize] {
        try {
          resize();
        } catch (...) {
          allocate_failed[n] = std::current_exception();
        }
      });
    };
    start(0, [&] { out.ct_hu.resize(n_out); });
    start(1, [&] {
      out.labels.resize(n_labels);
      out.outcome.resize(n_out);
    });
  }
  struct JoinOnExit {   // also when preparing throws: a joinable thread's destructor would terminate
    std::array<std::thread, 2>& threads;
    void join() {
      for (std::thread& t : threads)
        if (t.joinable()) t.join();
    }
    ~JoinOnExit() { join(); }
  } join_allocate{allocate};
  const CubeOrder order = cube_order(mesh);
  timer.lap("order");
  static_assert(std::is_trivially_destructible_v<RefTet> && alignof(RefTet) <= 64);
  RefTet* const tets = static_cast<RefTet*>(scratch.reserve(std::size_t(T) * sizeof(RefTet)));   // in cube order
#pragma omp parallel for schedule(static)
  for (int64_t n = 0; n < T; ++n) new (&tets[n]) RefTet(prepare(mesh, order.tets[std::size_t(n)], box));
  timer.lap("tetrahedra");
  const std::vector<TetGroup> groups = group_tetrahedra(order, tets);
  timer.lap("groups");

  Index3 tiles;
  for (int a = 0; a < 3; ++a) tiles[a] = (box.dims[a] + kTile[a] - 1) / kTile[a];
  const int64_t n_tiles = tiles[0] * tiles[1] * tiles[2];
  auto tile_of = [&](int a, int64_t i) { return (i - box.lo[a]) / kTile[a]; };
  std::vector<std::vector<int32_t>> by_tile(static_cast<std::size_t>(n_tiles));
  for (std::size_t n = 0; n < groups.size(); ++n) {
    const TetGroup& g = groups[n];
    for (int64_t c = tile_of(2, g.lo[2]); c <= tile_of(2, g.hi[2]); ++c)
      for (int64_t b = tile_of(1, g.lo[1]); b <= tile_of(1, g.hi[1]); ++b)
        for (int64_t a = tile_of(0, g.lo[0]); a <= tile_of(0, g.hi[0]); ++a)
          by_tile[std::size_t(a + tiles[0] * (b + tiles[1] * c))].push_back(int32_t(n));
  }

  timer.lap("tiles");
  join_allocate.join();
  for (const std::exception_ptr& e : allocate_failed)
    if (e) std::rethrow_exception(e);
  const SourceGrid grid{mesh.grid.dims, src.ct_hu, src.labels, src.roles};

  const int64_t nx = box.dims[0], ny = box.dims[1];
  // Cube column of each voxel column i (a table: an integer division per voxel costs more than the rest).
  std::vector<int64_t> cube_of_i(std::size_t(mesh.grid.dims[0]));
  for (int64_t i = 0; i < mesh.grid.dims[0]; ++i) cube_of_i[std::size_t(i)] = i / mesh.cube_voxels[0];
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
#pragma omp parallel reduction(+ : carried, gas, kept)
  {
    std::vector<int32_t> owner(std::size_t(kTile[0] * kTile[1] * kTile[2]));
    RowLanes lanes;
    GroupSpans spans;
#pragma omp for schedule(dynamic, 1)
    for (int64_t n_tile = 0; n_tile < n_tiles; ++n_tile) {
      Tile tile;
      const Index3 at{n_tile % tiles[0], (n_tile / tiles[0]) % tiles[1], n_tile / (tiles[0] * tiles[1])};
      for (int a = 0; a < 3; ++a) {
        tile.lo[a] = box.lo[a] + at[a] * kTile[a];
        tile.hi[a] = std::min(tile.lo[a] + kTile[a], box.lo[a] + box.dims[a]) - 1;
      }
      const int64_t tw = tile.hi[0] - tile.lo[0] + 1, th = tile.hi[1] - tile.lo[1] + 1;
      const int64_t tile_voxels = tw * th * (tile.hi[2] - tile.lo[2] + 1);
      std::fill_n(owner.begin(), tile_voxels, kNoOwner);
      for (int64_t k = tile.lo[2]; k <= tile.hi[2]; ++k)
        for (int64_t j = tile.lo[1]; j <= tile.hi[1]; ++j) std::fill_n(outcome + out_index(tile.lo[0], j, k), tw, WarpOutcome::Kept);
      int64_t tile_carried = 0;
      // 1. Scatter and sample, group by group over the box their bounding boxes share with this tile.
      // A tetrahedron's weights w and source point P′ − (d₀ + D w) are affine in the voxel index, so
      // each row starts from their value at the box's corner plus the row's offsets times their
      // steps, and each voxel adds its offset along the row times the step along i. Equal
      // displacements make D zero, so an identity or a whole-voxel translation still lands on whole
      // voxels exactly.
      for (int32_t n_group : by_tile[std::size_t(n_tile)]) {
        const TetGroup& group = groups[std::size_t(n_group)];
        Index3 lo, hi;
        for (int a = 0; a < 3; ++a) lo[a] = std::max(group.lo[a], tile.lo[a]), hi[a] = std::min(group.hi[a], tile.hi[a]);
        const Vec3 corner(static_cast<double>(lo[0]), static_cast<double>(lo[1]), static_cast<double>(lo[2]));
        for (int g = 0; g < kMaxGroup; ++g) {
          const bool in_group = g < group.count;
          spans.set_lane(g, in_group ? tets[std::size_t(group.first + g)] : kEmptyLane, corner, lanes);
          lanes.index[g] = in_group ? order.tets[std::size_t(group.first + g)] : INT32_MAX;
        }
        const int32_t t_max = int32_t(hi[0] - lo[0]);
        for (int64_t k = lo[2]; k <= hi[2]; ++k) {
          spans.plane(double(k - lo[2]));
          for (int64_t j = lo[1]; j <= hi[1]; ++j) {
            const auto [t_lo, t_hi] = spans.row(double(j - lo[1]), t_max, lanes);
            if (t_lo > t_hi) continue;
            const std::size_t row = out_index(lo[0], j, k);
            int32_t* const own = owner.data() + (lo[0] - tile.lo[0]) + tw * ((j - tile.lo[1]) + th * (k - tile.lo[2]));
            tile_carried += group.interior ? scatter_row<true>(lanes, group.part, grid, row, own, state)
                                           : scatter_row<false>(lanes, group.part, grid, row, own, state);
          }
        }
      }
      // 2. What no tetrahedron took: gas inside the meshes' space before or after deformation,
      // otherwise the voxel's own value. Nothing to do in a tile carried whole.
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
  }
  progress.finish();
  out.carried_voxels = carried;
  out.gas_voxels = gas;
  out.kept_voxels = kept;
  timer.lap("scatter and sample");
}

}  // namespace pneumo
