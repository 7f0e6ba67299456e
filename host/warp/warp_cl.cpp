// The image warp on an OpenCL device: buffers and launches of kernels/warp.cl.
#include <algorithm>
#include <climits>
#include <cmath>

#include "core/error.h"
#include "core/log.h"
#include "warp/phase_timer.h"
#include "warp/warp.h"

namespace pneumo {

namespace {

constexpr std::size_t kLocal = ocl::kWorkGroupSize;

cl_int4 int4_of(const Index3& v) { return {{cl_int(v[0]), cl_int(v[1]), cl_int(v[2]), 0}}; }

/// The kernel's per-tetrahedron records (8 float4, layout in kernels/warp.cl) and bounding boxes
/// (2 int4: first and last voxel centre, box-clipped; empty when first > last).
struct DeviceTets {
  std::vector<cl_float4> rec;
  std::vector<cl_int4> bbox;
};

DeviceTets prepare_tets(const WarpMesh& m, const WarpBox& box) {
  const int64_t T = m.tet_count();
  DeviceTets d;
  d.rec.assign(std::size_t(8 * T), cl_float4{{0, 0, 0, 0}});
  d.bbox.assign(std::size_t(2 * T), cl_int4{{1, 1, 1, 0}});
  auto f4 = [](const Vec3& v, double w) { return cl_float4{{float(v[0]), float(v[1]), float(v[2]), float(w)}}; };
#pragma omp parallel for schedule(static)
  for (int64_t t = 0; t < T; ++t) {
    cl_int4* bb = &d.bbox[std::size_t(2 * t)];
    bb[1] = cl_int4{{0, 0, 0, 0}};   // lo (1,1,1) > hi (0,0,0): nothing to visit
    if (warp_tet_degenerate(m, t)) continue;
    const auto& v = m.tets[std::size_t(t)];
    Vec3 x[4];
    for (int c = 0; c < 4; ++c) x[c] = m.deformed_ijk(v[c]);
    Mat3 e;
    e << x[1] - x[0], x[2] - x[0], x[3] - x[0];
    const Mat3 inv = e.inverse();
    const Vec3 d0 = m.disp_ijk[v[0]];
    Mat3 dd;
    dd << m.disp_ijk[v[1]] - d0, m.disp_ijk[v[2]] - d0, m.disp_ijk[v[3]] - d0;
    cl_float4* r = &d.rec[std::size_t(8 * t)];
    r[0] = f4(x[0], m.tet_part[std::size_t(t)] == Part::Wall ? 0.0 : 1.0);
    for (int row = 0; row < 3; ++row) r[1 + row] = f4(inv.row(row).transpose(), 0.0);
    r[4] = f4(d0, 0.0);
    for (int row = 0; row < 3; ++row) r[5 + row] = f4(dd.row(row).transpose(), 0.0);
    cl_int4 lo{{0, 0, 0, 0}}, hi{{0, 0, 0, 0}};
    bool empty = false;
    for (int a = 0; a < 3; ++a) {
      double mn = x[0][a], mx = x[0][a];
      for (int c = 1; c < 4; ++c) mn = std::min(mn, x[c][a]), mx = std::max(mx, x[c][a]);
      // Weights ≥ −tol reach at most 3·tol of the extent past the box; float rounding adds ~1e-5.
      const double margin = 4.0 * kWarpTolerance * (mx - mn) + 1e-3;
      const int64_t l = std::max<int64_t>(box.lo[a], int64_t(std::ceil(mn - margin)));
      const int64_t h = std::min<int64_t>(box.lo[a] + box.dims[a] - 1, int64_t(std::floor(mx + margin)));
      lo.s[a] = cl_int(l);
      hi.s[a] = cl_int(h);
      empty |= l > h;
    }
    if (!empty) bb[0] = lo, bb[1] = hi;
  }
  return d;
}

// Uploads return before their copies end (the sources outlive the warp's finish()).
template <class T>
cl::Buffer upload_async(ocl::Context& ctx, const T* data, std::size_t count) {
  return ocl::upload(ctx, data, count, CL_MEM_READ_ONLY, false);
}

}  // namespace

uint64_t warp_device_bytes(const WarpMesh& mesh, bool has_labels, const WarpBox& box) {
  // Source CT, roles and labels; owner, CT, labels and outcome per output voxel (without labels, a
  // one-entry stand-in for each label buffer); tetrahedra (a record and a bounding box, at least one);
  // the rest-space lattice (a byte per cube, a cube index per grid index along each axis).
  const uint64_t src_bytes = uint64_t(mesh.grid.voxel_count()) * (4 + 1 + (has_labels ? 2 : 0));
  const uint64_t out_bytes = uint64_t(box.voxel_count()) * (4 + 4 + 1 + (has_labels ? 2 : 0));
  const uint64_t no_labels_bytes = has_labels ? 0 : 2 * 2;
  const uint64_t tet_bytes = uint64_t(std::max<int64_t>(mesh.tet_count(), 1)) * (8 * 16 + 2 * 16);
  const Index3& d = mesh.grid.dims;
  const uint64_t lattice_bytes = std::max<uint64_t>(mesh.cube_meshed.size(), 1) + uint64_t(d[0] + d[1] + d[2]) * 4;
  return src_bytes + out_bytes + no_labels_bytes + tet_bytes + lattice_bytes;
}

WarpResult warp_opencl(ocl::Context& ctx, const WarpMesh& mesh, const WarpSource& src, const WarpBox& box,
                       const WarpOptions& opt) {
  check_warp_mesh(mesh);
  const int64_t T = mesh.tet_count();
  const int64_t n_src = mesh.grid.voxel_count(), n_out = box.voxel_count();
  // The kernel indexes 8 values per tetrahedron in int.
  if (T >= INT_MAX / 8) throw InputError("the warp handles at most 2^28 tetrahedra");
  ocl::require_features(ctx.info(), kLocal, 0);
  const bool has_labels = src.labels != nullptr;
  ctx.check_fits(warp_device_bytes(mesh, has_labels, box),
                 std::max<uint64_t>(uint64_t(n_src) * 4, uint64_t(n_out) * 4), "the image warp");

  PhaseTimer timer("warp on " + ctx.info().spec());
  WarpResult out;
  out.device = ctx.info().spec() + " " + ctx.info().name;
  const DeviceTets dt = prepare_tets(mesh, box);
  timer.lap("prepare");
  cl::Buffer tet = upload_async(ctx, dt.rec.data(), dt.rec.size());
  cl::Buffer bbox = upload_async(ctx, dt.bbox.data(), dt.bbox.size());
  cl::Buffer ct = upload_async(ctx, src.ct_hu, std::size_t(n_src));
  static_assert(sizeof(Role) == 1, "roles upload as uchar");
  cl::Buffer roles = upload_async(ctx, reinterpret_cast<const uint8_t*>(src.roles), std::size_t(n_src));
  cl::Buffer labels = upload_async(ctx, src.labels, has_labels ? std::size_t(n_src) : 0);
  cl::Buffer cubes = upload_async(ctx, mesh.cube_meshed.data(), mesh.cube_meshed.size());
  // The cube of every working-grid index, axis after axis (every index lies in the lattice: it has
  // ceil(dims / L) cubes per axis, L that axis's).
  std::vector<cl_int> cube_of_host;
  for (int a = 0; a < 3; ++a)
    for (int64_t i = 0; i < mesh.grid.dims[a]; ++i) cube_of_host.push_back(cl_int(i / mesh.cube_voxels[a]));
  cl::Buffer cube_of = upload_async(ctx, cube_of_host.data(), cube_of_host.size());
  cl::Buffer owner(ctx.context(), CL_MEM_READ_WRITE, std::size_t(n_out) * sizeof(cl_int));
  ctx.queue().enqueueFillBuffer(owner, cl_int(INT_MAX), 0, std::size_t(n_out) * sizeof(cl_int));
  cl::Buffer out_ct(ctx.context(), CL_MEM_WRITE_ONLY, std::size_t(n_out) * sizeof(float));
  cl::Buffer out_labels(ctx.context(), CL_MEM_WRITE_ONLY, std::size_t(has_labels ? n_out : 1) * sizeof(uint16_t));
  cl::Buffer out_outcome(ctx.context(), CL_MEM_WRITE_ONLY, std::size_t(n_out));

  ctx.queue().finish();
  timer.lap("upload");
  const cl_int4 src_dims = int4_of(mesh.grid.dims), box_lo = int4_of(box.lo), box_dims = int4_of(box.dims);
  cl::Kernel scatter = ctx.kernel("warp.cl", "warp_scatter");
  ocl::set_args(scatter, tet, bbox, cl_int(T), roles, src_dims, box_lo, box_dims, cl_float(kWarpTolerance), owner);
  const std::size_t tet_global = (std::size_t(T) + kLocal - 1) / kLocal * kLocal;
  if (T > 0) ctx.queue().enqueueNDRangeKernel(scatter, cl::NullRange, cl::NDRange(tet_global), cl::NDRange(kLocal));

  ctx.queue().finish();
  timer.lap("scatter");
  cl::Kernel sample = ctx.kernel("warp.cl", "warp_sample");
  const int64_t chunk = opt.row_chunk > 0 ? opt.row_chunk : ctx.info().type == "cpu" ? 32 : 1;
  ocl::set_args(sample, tet, owner, cl_int(T), ct, labels, cl_int(has_labels ? 1 : 0), src_dims, box_lo, box_dims,
                cubes, int4_of(Index3{mesh.cubes[0], mesh.cubes[1], mesh.cubes[2]}), cube_of,
                cl_float(opt.gas_hu), cl_ushort(opt.cavity_label), cl_int(chunk), out_ct, out_labels, out_outcome);
  const int64_t items = (box.dims[0] + chunk - 1) / chunk * box.dims[1] * box.dims[2];
  ctx.queue().enqueueNDRangeKernel(sample, cl::NullRange, cl::NDRange((std::size_t(items) + kLocal - 1) / kLocal * kLocal),
                                   cl::NDRange(kLocal));
  ctx.queue().finish();
  timer.lap("sample");
  out.ct_hu.resize(std::size_t(n_out));
  out.outcome.resize(std::size_t(n_out));
  static_assert(sizeof(WarpOutcome) == 1, "outcomes download as uchar");
  ctx.queue().enqueueReadBuffer(out_ct, CL_FALSE, 0, std::size_t(n_out) * sizeof(float), out.ct_hu.data());
  ctx.queue().enqueueReadBuffer(out_outcome, CL_FALSE, 0, std::size_t(n_out), out.outcome.data());
  if (has_labels) {
    out.labels.resize(std::size_t(n_out));
    ctx.queue().enqueueReadBuffer(out_labels, CL_FALSE, 0, std::size_t(n_out) * sizeof(uint16_t), out.labels.data());
  }
  ctx.queue().finish();
  timer.lap("download");
  for (WarpOutcome w : out.outcome)
    ++(w == WarpOutcome::Carried ? out.carried_voxels : w == WarpOutcome::Gas ? out.gas_voxels : out.kept_voxels);
  timer.lap("count");
  return out;
}

}  // namespace pneumo
