// The warp stage's one entry: the device spec picks the back end (warp.h), here and nowhere else.
#include "cl/cl_runtime.h"
#include "core/log.h"
#include "warp/cavity_enclosure.h"
#include "warp/warp.h"

namespace pneumo {

WarpResult warp_on_device(ocl::Context* ctx, const WarpMesh& mesh, const WarpSource& src, const WarpBox& box,
                          const WarpOptions& opt) {
  WarpResult r = ctx ? warp_opencl(*ctx, mesh, src, box, opt) : warp_cpu(mesh, src, box, opt);
  enclose_cavity(r, mesh, src, box, opt);
  return r;
}

WarpResult warp_on_device(const std::string& device, const WarpMesh& mesh, const WarpSource& src, const WarpBox& box,
                          const WarpOptions& opt) {
  const ocl::DeviceSpec spec = ocl::parse_device_spec(device);
  if (!spec.use_opencl) return warp_on_device(nullptr, mesh, src, box, opt);
  auto ctx = ocl::Context::shared(spec);
  log::info("warping on " + ctx->info().spec() + " " + ctx->info().name);
  return warp_on_device(ctx.get(), mesh, src, box, opt);
}

const WarpResult& WarpSeries::warp(const std::string& device, const WarpMesh& mesh, const WarpSource& src,
                                   const WarpBox& box, const WarpOptions& opt) {
  try {
    if (ocl::parse_device_spec(device).use_opencl) {
      result_ = WarpResult{};   // the last outputs go before the next are allocated
      result_ = warp_on_device(device, mesh, src, box, opt);
    } else {
      warp_cpu(mesh, src, box, opt, result_, scratch_);
      enclose_cavity(result_, mesh, src, box, opt);
    }
  } catch (...) {
    result_ = WarpResult{};   // no half-written result that looks like one
    throw;
  }
  return result_;
}

}  // namespace pneumo
