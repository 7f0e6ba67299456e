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

/// "opencl:0:1" → "opencl_0_1" (test names allow no colons).
inline std::string spec_name(std::string spec) {
  for (char& ch : spec)
    if (ch == ':') ch = '_';
  return spec;
}

}  // namespace pneumo::testing_support
