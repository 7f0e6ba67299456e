#pragma once
// The barycentric image warp (method.md §7; Kitasaka §2.5, Nimura §2.4): the deformed CT and label
// map from the rest and deformed meshes. One entry, warp_on_device (warp_on_device.cpp), over three
// implementations of the rules below: warp_reference (warp_reference.cpp: the plain voxel loop, one
// thread, double precision; the tests' oracle), warp_cpu (warp_cpu.cpp: the fast CPU back end,
// double precision, OpenMP over tiles, row spans in SSE2) and warp_opencl (warp_cl.cpp,
// kernels/warp.cl, float32). Tests hold warp_cpu to the reference and the kernel to warp_cpu.
//
// For each output voxel centre P′ (index coordinates of the working grid, warp_mesh.h):
//  1. Scatter: each deformed tetrahedron visits the voxel centres of its bounding box; P′ is inside
//     when its barycentric weights w are all ≥ −kWarpTolerance. Its source point is
//     P = P′ − (d₀ + Σ_{i=1..3} w_i (d_i − d₀)), d the node displacements: the same affine map as
//     P = Σ w_i x_i(0), written so that equal displacements cancel exactly.
//  2. Acceptance: a wall tetrahedron takes P only if the role at P (nearest voxel) is not viscera,
//     a viscera tetrahedron only if it is not wall. This splits doubled cubes along the true
//     interface. Of several accepting tetrahedra the lowest index wins (any rule independent of
//     the visiting order keeps the result deterministic; on shared faces the map is continuous,
//     so which one wins changes nothing but rounding).
//  3. Sampling: CT trilinear at P, label nearest at P. A source outside the working grid reads
//     air: −1000 HU, label 0, role other (what the roles' padding holds).
//  4. No accepted tetrahedron: gas (−1000 HU, the cavity label) when the voxel is inside the space
//     the meshes occupied before (a cube meshed at rest) or after (inside some deformed
//     tetrahedron) deformation; otherwise the voxel keeps its own value.
//  5. Enclosed: a voxel rule 4 kept that was outside the body at rest is gas when the deformed
//     body encloses it in its axial slice (the space between the skin's rest place and the wall's
//     inner face when the wall rises by more than its thickness; cavity_enclosure.h). The back ends
//     compute rules 1–4; warp_on_device and WarpSeries apply rule 5 to every back end's result.
#include <cstdint>
#include <string>
#include <vector>

#include "cl/cl_runtime.h"
#include "core/reusable_buffer.h"
#include "domain/types.h"
#include "warp/warp_mesh.h"

namespace pneumo {

/// What the warp samples: the working grid's voxels (WarpMesh::grid), i fastest.
struct WarpSource {
  const float* ct_hu = nullptr;
  const uint16_t* labels = nullptr;   // null: no label output
  const Role* roles = nullptr;        // required: acceptance reads it
};

/// The output box, in voxels of the working grid: the CT's own grid inside the padded one.
struct WarpBox {
  Index3 lo{0, 0, 0};
  Index3 dims{1, 1, 1};
  int64_t voxel_count() const { return dims[0] * dims[1] * dims[2]; }
};

struct WarpOptions {
  uint16_t cavity_label = 250;
  float gas_hu = -1000.0f;
  /// OpenCL only: output voxels of a row per work-item of the sample pass; 0 picks by device type
  /// (32 on a CPU, 1 on a GPU: kernels/warp.cl says why). The result does not depend on it.
  int row_chunk = 0;
};

/// What happened at each output voxel.
enum class WarpOutcome : uint8_t { Kept = 0, Carried = 1, Gas = 2 };

struct WarpResult {
  std::vector<float> ct_hu;          // box voxels, i fastest
  std::vector<uint16_t> labels;      // box voxels; empty when the source has no labels
  std::vector<WarpOutcome> outcome;  // box voxels
  int64_t carried_voxels = 0, gas_voxels = 0, kept_voxels = 0;
  std::string device;                // "cpu" or "opencl:P:D <name>"
};

/// The plain reference: warp.h's rules as a loop over tetrahedra and their boxes' voxels. Slow;
/// the tests' oracle (result device "cpu-reference").
WarpResult warp_reference(const WarpMesh& mesh, const WarpSource& src, const WarpBox& box, const WarpOptions& opt);

/// The fast CPU back end: the reference's result (equal but for ties decided by rounding, within
/// 1e-15 relative), deterministic for any thread count. Shows Progress("warp").
WarpResult warp_cpu(const WarpMesh& mesh, const WarpSource& src, const WarpBox& box, const WarpOptions& opt);
/// The same into `out`, reusing its outputs' memory where they already have the box's size, and
/// `scratch` for the prepared tetrahedra (256 bytes each): what a series of warps keeps (WarpSeries).
void warp_cpu(const WarpMesh& mesh, const WarpSource& src, const WarpBox& box, const WarpOptions& opt,
              WarpResult& out, ReusableBuffer& scratch);

/// kernels/warp.cl on a device, float32. Checks the device's memory first (ctx.check_fits with
/// warp_device_bytes).
WarpResult warp_opencl(ocl::Context& ctx, const WarpMesh& mesh, const WarpSource& src, const WarpBox& box,
                       const WarpOptions& opt);

/// The device memory warp_opencl needs (bytes): what it allocates, every buffer counted.
uint64_t warp_device_bytes(const WarpMesh& mesh, bool has_labels, const WarpBox& box);

/// The stage's one entry, as solve_on_device: warp_opencl on `ctx` when given, warp_cpu otherwise,
/// then rule 5 (enclose_cavity).
WarpResult warp_on_device(ocl::Context* ctx, const WarpMesh& mesh, const WarpSource& src, const WarpBox& box,
                          const WarpOptions& opt);
/// The same for a device spec: "cpu", "opencl" or "opencl:P:D" (InputError for anything else).
WarpResult warp_on_device(const std::string& device, const WarpMesh& mesh, const WarpSource& src, const WarpBox& box,
                          const WarpOptions& opt);

/// Warps one after another into memory kept between them: a time-lapse's frames, a benchmark's
/// repetitions. The CPU warp of the peers' 512×512×300 case writes 400 MB of outputs and prepares
/// 200 MB of tetrahedra; faulting that in anew is a large share of a warp (measured in
/// bench/results/2026-12-01-warp.md), so a series faults it in once, as ITK's filters keep their
/// output buffer between updates. (OpenCL warps allocate their own host outputs.)
class WarpSeries {
 public:
  /// warp_on_device; the result is valid until the next warp. After a throw the series holds none.
  const WarpResult& warp(const std::string& device, const WarpMesh& mesh, const WarpSource& src, const WarpBox& box,
                         const WarpOptions& opt);
  /// The last warp's result.
  const WarpResult& result() const { return result_; }

 private:
  WarpResult result_;
  ReusableBuffer scratch_;
};

}  // namespace pneumo
