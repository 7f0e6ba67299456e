#pragma once
// What every section of `pneumo bench` shares: the devices, the bandwidth measured once per device in this run,
// the OpenCL contexts (held for the whole run: kernels compile once), timing with repetitions, and notes.
#include <chrono>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cl/cl_runtime.h"
#include "core/stopwatch.h"
#include "common/stats.h"

namespace pneumo::bench {

/// A place a stage can run: the CPU reference on some threads, or an OpenCL device.
struct Device {
  std::string name;       // "cpu_1thread", "cpu_2threads", "opencl:0:0"
  int threads = 0;        // CPU: OpenMP threads; 0 for OpenCL
  ocl::DeviceInfo info;   // OpenCL only
  bool opencl() const { return threads == 0; }
  std::string description() const;   // "CPU reference, double, 2 threads" / "<device name>, float32"
};

class BenchContext {
 public:
  explicit BenchContext(bool quick);

  bool quick() const { return quick_; }
  const std::vector<Device>& devices() const { return devices_; }
  /// STREAM triad on this device (native on its threads, or the OpenCL kernel), measured at the first call.
  double bandwidth_gb_s(const Device& d);
  nlohmann::json bandwidth_json() const { return bandwidth_; }
  /// The device's context, opened once.
  ocl::Context& cl(const Device& d);

  void note(const std::string& text);
  const std::vector<std::string>& notes() const { return notes_; }

 private:
  bool quick_;
  std::vector<Device> devices_;
  std::map<std::string, double> bandwidth_cache_;
  nlohmann::json bandwidth_ = nlohmann::json::object();
  std::map<std::string, std::shared_ptr<ocl::Context>> contexts_;
  std::vector<std::string> notes_;
};

/// Runs `fn` with OpenMP limited to `threads` (all when 0), restoring the previous limit after.
void with_threads(int threads, const std::function<void()>& fn);

/// Times `reps` calls of `fn` (after `warmups` untimed ones): seconds per call, summarised.
Summary time_reps(int reps, int warmups, const std::function<void()>& fn);


}  // namespace pneumo::bench
