#pragma once
// The OpenCL runtime: which devices exist, which one a run uses, and the programs built for it.
// One Context per device per process; programs are built once per (sources, options) and cached.
// Nothing here branches on the device type: the same code runs on PoCL and on a GPU.
#include <CL/opencl.hpp>

#include <algorithm>
#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <cstddef>
#include <string>
#include <vector>

namespace pneumo::ocl {

/// The work-group size every pneumo kernel is launched with, fixed (PoCL compiles a kernel once per
/// size). The one place it is written: kernels see it as PNEUMO_WORK_GROUP (default_build_options).
constexpr std::size_t kWorkGroupSize = 64;

/// The global size that covers n work items (at least one) in whole work-groups of kWorkGroupSize;
/// kernels return early for ids ≥ n.
inline std::size_t global_size(int64_t n) {
  return (std::size_t(n > 1 ? n : 1) + kWorkGroupSize - 1) / kWorkGroupSize * kWorkGroupSize;
}

struct DeviceInfo {
  int platform_index = -1, device_index = -1;
  std::string platform_name, platform_version;
  std::string name, vendor, version, driver_version, opencl_c_version;
  std::string type;               // "cpu", "gpu", "accelerator", "other"
  unsigned compute_units = 0;
  uint64_t global_mem_bytes = 0, max_alloc_bytes = 0, local_mem_bytes = 0;
  std::size_t max_work_group_size = 0;
  bool fp64 = false;
  std::string spec() const;       // "opencl:P:D"
};

/// Every device of every platform. No platform is an empty list, not an error.
std::vector<DeviceInfo> list_devices();

/// Why list_devices() may be empty on this machine (ICD files, PoCL's cache folder), for messages.
std::string no_device_hint();

/// The device "auto" stands for among `devices`: the first GPU or accelerator ("opencl:P:D"), or
/// "cpu" (the C++ reference) where there is none. An OpenCL device of type CPU (PoCL) runs on the
/// cores the reference runs on, and was slower than it at every stage measured on the default
/// finite elements (docs/performance.md, "Which device": the large phantom's warp 6.1 s against
/// 3.6 s, the medium phantom's `balanced` run 20.9 s against 7.4 s).
std::string auto_device(const std::vector<DeviceInfo>& devices);

/// What the user asked for: "cpu" (the plain C++ reference), "opencl" (first OpenCL device),
/// "opencl:P:D", or "auto" (auto_device of the devices this machine has, chosen once per process;
/// `text` then names the device chosen). Throws InputError for anything else.
struct DeviceSpec {
  bool use_opencl = false;
  int platform = -1, device = -1;   // -1: the first one found
  std::string text;
};
DeviceSpec parse_device_spec(const std::string& text);

class Context {
 public:
  /// Opens the device the spec names; throws InputError naming the spec and the devices that exist.
  static std::shared_ptr<Context> open(const DeviceSpec& spec);
  /// The same Context for the same device within one process.
  static std::shared_ptr<Context> shared(const DeviceSpec& spec);

  const DeviceInfo& info() const { return info_; }
  cl::Context& context() { return context_; }
  cl::CommandQueue& queue() { return queue_; }
  cl::Device& device() { return device_; }

  /// Builds (once) the program made of the given kernels/ files, in order, with `options`
  /// appended to the defaults. A failed build throws with the device, the options and the log.
  cl::Program& program(const std::vector<std::string>& kernel_files, const std::string& options = "");
  /// Builds a program from a source string (tests and tools); same caching and error reporting.
  cl::Program& program_from_source(const std::string& name, const std::string& source, const std::string& options = "");
  cl::Kernel kernel(const std::string& kernel_file, const std::string& kernel_name, const std::string& options = "");

  /// Throws a clear error naming this device if `bytes` of buffers (the largest being
  /// `largest_buffer_bytes`) would not fit; call before allocating a case.
  void check_fits(uint64_t bytes, uint64_t largest_buffer_bytes, const std::string& what) const;

  /// Build options every program gets: OpenCL C 1.2, PNEUMO_WORK_GROUP defined as kWorkGroupSize,
  /// no fast-math, so results stay comparable with the CPU reference.
  static const std::string& default_build_options();

 private:
  Context(const cl::Device& d, const DeviceInfo& info);
  DeviceInfo info_;
  cl::Device device_;
  cl::Context context_;
  cl::CommandQueue queue_;
  std::mutex mutex_;
  std::map<std::string, cl::Program> programs_;
};

/// What a device lacks for pneumo's kernels ("" when nothing): OpenCL C ≥ 1.2, a work-group of at
/// least `work_group` items, `local_bytes` of local memory. Pure, so it can be tested on any info.
std::string missing_features(const DeviceInfo& info, std::size_t work_group, uint64_t local_bytes);
/// Throws InputError naming the device and what it lacks.
void require_features(const DeviceInfo& info, std::size_t work_group, uint64_t local_bytes);

/// Sets a kernel's arguments in order: set_args(k, a, b, c) is k.setArg(0, a); k.setArg(1, b); ...
template <class... A>
void set_args(cl::Kernel& k, const A&... a) {
  cl_uint i = 0;
  (k.setArg(i++, a), ...);
}

/// A buffer holding `count` elements from `data`, with room for one at least (OpenCL refuses empty buffers).
/// `blocking` false returns before the copy ends: `data` must then live until the queue's next finish().
template <class T>
cl::Buffer upload(Context& ctx, const T* data, std::size_t count, cl_mem_flags flags = CL_MEM_READ_ONLY,
                  bool blocking = true) {
  cl::Buffer b(ctx.context(), flags, std::max<std::size_t>(count, 1) * sizeof(T));
  if (count) ctx.queue().enqueueWriteBuffer(b, blocking ? CL_TRUE : CL_FALSE, 0, count * sizeof(T), data);
  return b;
}
template <class T>
cl::Buffer upload(Context& ctx, const std::vector<T>& data, cl_mem_flags flags = CL_MEM_READ_ONLY) {
  return upload(ctx, data.data(), data.size(), flags);
}

/// Expands `#include "x.cl"` lines from the embedded kernels (each file once).
std::string expand_includes(const std::string& source, const std::string& name);

/// Human-readable name of an OpenCL error code (e.g. -61 → "CL_INVALID_BUFFER_SIZE").
const char* error_name(cl_int code);

}  // namespace pneumo::ocl
