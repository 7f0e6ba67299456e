#include "cl/cl_runtime.h"

#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <cstdio>
#include <functional>
#include <regex>
#include <set>
#include <sstream>

#include "cl/embedded_kernels.h"
#include "core/error.h"
#include "core/log.h"

namespace pneumo::ocl {

namespace {

// PoCL lists no device at all, silently, when it cannot create its cache folder
// (platform.md). Give it a private one under /tmp when the default is not writable.
void ensure_pocl_cache_dir() {
  static std::once_flag once;
  std::call_once(once, [] {
    if (std::getenv("POCL_CACHE_DIR")) return;
    std::string base;
    if (const char* x = std::getenv("XDG_CACHE_HOME")) base = x;
    else if (const char* h = std::getenv("HOME")) base = std::string(h) + "/.cache";
    std::error_code ec;
    if (!base.empty()) {
      std::filesystem::create_directories(base + "/pocl", ec);
      if (!ec && ::access((base + "/pocl").c_str(), W_OK) == 0) return;
    }
    const std::string dir = "/tmp/pneumo-pocl-cache-" + std::to_string(::getuid());
    std::filesystem::create_directories(dir, ec);
    ::setenv("POCL_CACHE_DIR", dir.c_str(), 0);
  });
}

std::string device_type_name(cl_device_type t) {
  if (t & CL_DEVICE_TYPE_GPU) return "gpu";
  if (t & CL_DEVICE_TYPE_CPU) return "cpu";
  if (t & CL_DEVICE_TYPE_ACCELERATOR) return "accelerator";
  return "other";
}

std::vector<std::pair<cl::Device, DeviceInfo>> enumerate() {
  ensure_pocl_cache_dir();
  std::vector<std::pair<cl::Device, DeviceInfo>> out;
  std::vector<cl::Platform> platforms;
  try {
    cl::Platform::get(&platforms);
  } catch (const cl::Error&) {
    return out;  // CL_PLATFORM_NOT_FOUND_KHR: no ICD installed
  }
  for (std::size_t p = 0; p < platforms.size(); ++p) {
    std::vector<cl::Device> devices;
    try {
      platforms[p].getDevices(CL_DEVICE_TYPE_ALL, &devices);
    } catch (const cl::Error&) {
      continue;
    }
    for (std::size_t d = 0; d < devices.size(); ++d) {
      const cl::Device& dev = devices[d];
      DeviceInfo i;
      i.platform_index = int(p);
      i.device_index = int(d);
      i.platform_name = platforms[p].getInfo<CL_PLATFORM_NAME>();
      i.platform_version = platforms[p].getInfo<CL_PLATFORM_VERSION>();
      i.name = dev.getInfo<CL_DEVICE_NAME>();
      i.vendor = dev.getInfo<CL_DEVICE_VENDOR>();
      i.version = dev.getInfo<CL_DEVICE_VERSION>();
      i.driver_version = dev.getInfo<CL_DRIVER_VERSION>();
      i.opencl_c_version = dev.getInfo<CL_DEVICE_OPENCL_C_VERSION>();
      i.type = device_type_name(dev.getInfo<CL_DEVICE_TYPE>());
      i.compute_units = dev.getInfo<CL_DEVICE_MAX_COMPUTE_UNITS>();
      i.global_mem_bytes = dev.getInfo<CL_DEVICE_GLOBAL_MEM_SIZE>();
      i.max_alloc_bytes = dev.getInfo<CL_DEVICE_MAX_MEM_ALLOC_SIZE>();
      i.local_mem_bytes = dev.getInfo<CL_DEVICE_LOCAL_MEM_SIZE>();
      i.max_work_group_size = dev.getInfo<CL_DEVICE_MAX_WORK_GROUP_SIZE>();
      i.fp64 = dev.getInfo<CL_DEVICE_EXTENSIONS>().find("cl_khr_fp64") != std::string::npos;
      for (auto* s : {&i.platform_name, &i.name, &i.vendor, &i.version, &i.driver_version, &i.opencl_c_version})
        while (!s->empty() && (s->back() == '\0' || s->back() == ' ')) s->pop_back();
      out.emplace_back(dev, i);
    }
  }
  return out;
}

}  // namespace

std::string DeviceInfo::spec() const {
  return "opencl:" + std::to_string(platform_index) + ":" + std::to_string(device_index);
}

std::vector<DeviceInfo> list_devices() {
  std::vector<DeviceInfo> out;
  for (auto& [dev, info] : enumerate()) out.push_back(info);
  return out;
}

std::string no_device_hint() {
  return "no OpenCL device found: install an ICD (e.g. pocl-opencl-icd, listed in /etc/OpenCL/vendors) and, for "
         "PoCL, make sure POCL_CACHE_DIR (now " +
         std::string(std::getenv("POCL_CACHE_DIR") ? std::getenv("POCL_CACHE_DIR") : "unset") +
         ") is a writable folder; POCL_DEBUG=1 shows why a platform has no device";
}

std::string auto_device(const std::vector<DeviceInfo>& devices) {
  for (const DeviceInfo& d : devices)
    if (d.type == "gpu" || d.type == "accelerator") return d.spec();
  return "cpu";
}

DeviceSpec parse_device_spec(const std::string& text) {
  if (text == "auto") {
    static const std::string chosen = [] {
      const std::string c = auto_device(list_devices());
      log::info("device auto: " + c + (c == "cpu" ? " (no OpenCL GPU or accelerator)" : ""));
      return c;
    }();
    return parse_device_spec(chosen);
  }
  DeviceSpec s;
  s.text = text;
  if (text == "cpu") return s;
  s.use_opencl = true;
  if (text == "opencl") return s;
  static const std::regex re(R"(opencl:(\d{1,3}):(\d{1,3}))");
  std::smatch m;
  if (std::regex_match(text, m, re)) {
    s.platform = std::stoi(m[1]);
    s.device = std::stoi(m[2]);
    return s;
  }
  throw InputError("device '" + text + "' is not valid: use cpu, auto, opencl or opencl:P:D (see `pneumo devices`)");
}

Context::Context(const cl::Device& d, const DeviceInfo& info)
    : info_(info), device_(d), context_(d), queue_(context_, d) {}

std::shared_ptr<Context> Context::open(const DeviceSpec& spec) {
  if (!spec.use_opencl) throw std::logic_error("Context::open called for the CPU reference");
  auto all = enumerate();
  if (all.empty()) throw InputError("device '" + spec.text + "': " + no_device_hint());
  for (auto& [dev, info] : all) {
    const bool match = spec.platform < 0 || (info.platform_index == spec.platform && info.device_index == spec.device);
    if (match) {
      auto ctx = std::shared_ptr<Context>(new Context(dev, info));
      log::debug("OpenCL device " + info.spec() + ": " + info.name + " (" + info.platform_name + ", " +
                 info.version + ")");
      return ctx;
    }
  }
  std::string have;
  for (auto& [dev, info] : all) have += (have.empty() ? "" : ", ") + info.spec() + " " + info.name;
  throw InputError("device '" + spec.text + "' does not exist; available: " + have);
}

std::shared_ptr<Context> Context::shared(const DeviceSpec& spec) {
  static std::mutex m;
  static std::map<std::string, std::weak_ptr<Context>> cache;
  std::lock_guard<std::mutex> lock(m);
  const std::string key = spec.platform < 0 ? "first" : std::to_string(spec.platform) + ":" + std::to_string(spec.device);
  if (auto existing = cache[key].lock()) return existing;
  auto ctx = open(spec);
  cache[key] = ctx;
  return ctx;
}

const std::string& Context::default_build_options() {
  static const std::string options = "-cl-std=CL1.2 -DPNEUMO_WORK_GROUP=" + std::to_string(kWorkGroupSize);
  return options;
}

cl::Program& Context::program_from_source(const std::string& name, const std::string& source,
                                          const std::string& options) {
  const std::string opts = default_build_options() + (options.empty() ? "" : " " + options);
  const std::string key = name + "\n" + opts + "\n" + source;
  std::lock_guard<std::mutex> lock(mutex_);
  auto it = programs_.find(key);
  if (it != programs_.end()) return it->second;
  cl::Program prog(context_, source);
  try {
    log::debug("building " + name + " for " + info_.name + " with '" + opts + "'");
    prog.build(std::vector<cl::Device>{device_}, opts.c_str());
  } catch (const cl::Error& e) {
    std::string build_log;
    try {
      build_log = prog.getBuildInfo<CL_PROGRAM_BUILD_LOG>(device_);
    } catch (const cl::Error&) {
      build_log = "(no build log)";
    }
    throw std::runtime_error("OpenCL build of " + name + " failed on " + info_.spec() + " " + info_.name + " (" +
                             info_.platform_name + ") with options '" + opts + "': " + error_name(e.err()) +
                             "\nbuild log:\n" + build_log);
  }
  return programs_.emplace(key, prog).first->second;
}

cl::Program& Context::program(const std::vector<std::string>& kernel_files, const std::string& options) {
  std::string source, name;
  for (const auto& f : kernel_files) {
    source += expand_includes(kernel_source(f), f);
    name += (name.empty() ? "" : "+") + f;
  }
  return program_from_source(name, source, options);
}

cl::Kernel Context::kernel(const std::string& kernel_file, const std::string& kernel_name, const std::string& options) {
  cl::Program& p = program({kernel_file}, options);
  try {
    return cl::Kernel(p, kernel_name.c_str());
  } catch (const cl::Error& e) {
    throw std::runtime_error("kernel " + kernel_name + " not found in " + kernel_file + " on " + info_.name + ": " +
                             error_name(e.err()));
  }
}

void Context::check_fits(uint64_t bytes, uint64_t largest_buffer_bytes, const std::string& what) const {
  auto mib = [](uint64_t b) { return std::to_string((b + (1u << 20) - 1) >> 20) + " MiB"; };
  if (largest_buffer_bytes > info_.max_alloc_bytes)
    throw InputError(what + " needs a single buffer of " + mib(largest_buffer_bytes) + ", more than the " +
                     mib(info_.max_alloc_bytes) + " device " + info_.spec() + " (" + info_.name +
                     ") allows per buffer: use a larger cube size or a region of interest");
  if (bytes > info_.global_mem_bytes)
    throw InputError(what + " needs about " + mib(bytes) + " of device memory, more than the " +
                     mib(info_.global_mem_bytes) + " of " + info_.spec() + " (" + info_.name +
                     "): use a larger cube size or a region of interest");
}

std::string missing_features(const DeviceInfo& info, std::size_t work_group, uint64_t local_bytes) {
  std::string missing;
  auto add = [&](const std::string& what) { missing += (missing.empty() ? "" : "; ") + what; };
  // "OpenCL C 1.2 ..." / "OpenCL C 3.0 ...": the major and minor numbers after "OpenCL C ".
  int major = 0, minor = 0;
  if (std::sscanf(info.opencl_c_version.c_str(), "OpenCL C %d.%d", &major, &minor) != 2 || major * 10 + minor < 12)
    add("OpenCL C 1.2 (it reports '" + info.opencl_c_version + "')");
  if (info.max_work_group_size < work_group)
    add("work-groups of " + std::to_string(work_group) + " items (it allows " +
        std::to_string(info.max_work_group_size) + ")");
  if (info.local_mem_bytes < local_bytes)
    add(std::to_string(local_bytes) + " bytes of local memory (it has " + std::to_string(info.local_mem_bytes) + ")");
  return missing;
}

void require_features(const DeviceInfo& info, std::size_t work_group, uint64_t local_bytes) {
  const std::string missing = missing_features(info, work_group, local_bytes);
  if (!missing.empty())
    throw InputError("device " + info.spec() + " (" + info.name + ") cannot run pneumo's kernels: it lacks " + missing);
}

std::string expand_includes(const std::string& source, const std::string& name) {
  static const std::regex inc(R"re(^\s*#\s*include\s*"([^"]+)"\s*$)re");
  std::set<std::string> seen;
  std::function<std::string(const std::string&, const std::string&)> expand = [&](const std::string& src,
                                                                                  const std::string& from) {
    std::istringstream in(src);
    std::ostringstream out;
    std::string line;
    int line_no = 0;
    while (std::getline(in, line)) {
      ++line_no;
      std::smatch m;
      if (std::regex_match(line, m, inc)) {
        const std::string file = m[1];
        if (seen.insert(file).second) out << expand(kernel_source(file), file);
        out << "#line " << line_no + 1 << "\n";  // keep build-log line numbers meaningful
        continue;
      }
      out << line << "\n";
    }
    (void)from;
    return out.str();
  };
  seen.insert(name);
  return expand(source, name);
}

const char* error_name(cl_int code) {
  switch (code) {
#define PNEUMO_CL_ERR(x) case x: return #x;
    PNEUMO_CL_ERR(CL_SUCCESS) PNEUMO_CL_ERR(CL_DEVICE_NOT_FOUND) PNEUMO_CL_ERR(CL_DEVICE_NOT_AVAILABLE)
    PNEUMO_CL_ERR(CL_COMPILER_NOT_AVAILABLE) PNEUMO_CL_ERR(CL_MEM_OBJECT_ALLOCATION_FAILURE)
    PNEUMO_CL_ERR(CL_OUT_OF_RESOURCES) PNEUMO_CL_ERR(CL_OUT_OF_HOST_MEMORY) PNEUMO_CL_ERR(CL_BUILD_PROGRAM_FAILURE)
    PNEUMO_CL_ERR(CL_INVALID_VALUE) PNEUMO_CL_ERR(CL_INVALID_DEVICE) PNEUMO_CL_ERR(CL_INVALID_CONTEXT)
    PNEUMO_CL_ERR(CL_INVALID_MEM_OBJECT) PNEUMO_CL_ERR(CL_INVALID_BUILD_OPTIONS) PNEUMO_CL_ERR(CL_INVALID_PROGRAM)
    PNEUMO_CL_ERR(CL_INVALID_PROGRAM_EXECUTABLE) PNEUMO_CL_ERR(CL_INVALID_KERNEL_NAME) PNEUMO_CL_ERR(CL_INVALID_KERNEL)
    PNEUMO_CL_ERR(CL_INVALID_ARG_INDEX) PNEUMO_CL_ERR(CL_INVALID_ARG_VALUE) PNEUMO_CL_ERR(CL_INVALID_ARG_SIZE)
    PNEUMO_CL_ERR(CL_INVALID_KERNEL_ARGS) PNEUMO_CL_ERR(CL_INVALID_WORK_DIMENSION)
    PNEUMO_CL_ERR(CL_INVALID_WORK_GROUP_SIZE) PNEUMO_CL_ERR(CL_INVALID_GLOBAL_WORK_SIZE)
    PNEUMO_CL_ERR(CL_INVALID_BUFFER_SIZE) PNEUMO_CL_ERR(CL_INVALID_OPERATION)
#undef PNEUMO_CL_ERR
    default: return "CL_ERROR (unknown code)";
  }
}

}  // namespace pneumo::ocl
