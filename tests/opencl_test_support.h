#pragma once
// Per-device tests: every OpenCL device found, and a readable test-name suffix for each.
#include <string>
#include <vector>

#include "cl/cl_runtime.h"

namespace pneumo::testing_support {

inline std::vector<std::string> opencl_device_specs() {
  std::vector<std::string> specs;
  for (const auto& d : ocl::list_devices()) specs.push_back(d.spec());
  return specs;
}

/// "cpu" (the C++ reference) and then every OpenCL device: the --device values a test runs on all.
inline std::vector<std::string> cpu_and_opencl_device_specs() {
  std::vector<std::string> specs = {"cpu"};
  for (const std::string& spec : opencl_device_specs()) specs.push_back(spec);
  return specs;
}

/// "opencl:0:1" → "opencl_0_1" (test names allow no colons).
inline std::string spec_name(std::string spec) {
  for (char& ch : spec)
    if (ch == ':') ch = '_';
  return spec;
}

}  // namespace pneumo::testing_support
