#include <iostream>
#include <nlohmann/json.hpp>

#include "cl/cl_runtime.h"
#include "cli/commands.h"

namespace pneumo::cli {

Run add_devices(CLI::App& app) {
  auto* cmd = app.add_subcommand("devices", "List the compute devices: the CPU reference and every OpenCL device");
  auto json = std::make_shared<bool>(false);
  cmd->add_flag("--json", *json, "Print JSON");
  return [=] {
    const auto devices = ocl::list_devices();
    if (*json) {
      nlohmann::json list = nlohmann::json::array();
      list.push_back({{"spec", "cpu"}, {"name", "plain C++ reference (double precision, OpenMP)"}});
      for (const auto& d : devices)
        list.push_back({{"spec", d.spec()}, {"platform", d.platform_name}, {"name", d.name}, {"type", d.type},
                        {"vendor", d.vendor}, {"version", d.version}, {"opencl_c", d.opencl_c_version},
                        {"compute_units", d.compute_units}, {"global_mem_bytes", d.global_mem_bytes},
                        {"max_alloc_bytes", d.max_alloc_bytes}, {"local_mem_bytes", d.local_mem_bytes},
                        {"max_work_group_size", d.max_work_group_size}, {"fp64", d.fp64}});
      std::cout << list.dump(2) << "\n";
      return 0;
    }
    std::cout << "cpu          plain C++ reference (double precision, OpenMP)\n";
    for (const auto& d : devices) {
      std::printf("%-12s %s [%s] on %s\n", d.spec().c_str(), d.name.c_str(), d.type.c_str(), d.platform_name.c_str());
      std::printf("             %s, %u compute units, %.1f GiB memory (%.1f GiB per buffer), fp64 %s\n",
                  d.version.c_str(), d.compute_units, d.global_mem_bytes / 1073741824.0,
                  d.max_alloc_bytes / 1073741824.0, d.fp64 ? "yes" : "no");
    }
    if (devices.empty()) std::cout << "(" << ocl::no_device_hint() << ")\n";
    return 0;
  };
}

}  // namespace pneumo::cli
