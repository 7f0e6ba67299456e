#include "common/cpu_load.h"

#include <algorithm>
#include <cstdio>
#include <cstring>

#include <unistd.h>

namespace pneumo::bench {

CpuSample cpu_sample() {
  CpuSample s;
  const double tick = double(::sysconf(_SC_CLK_TCK));
  if (std::FILE* f = std::fopen("/proc/stat", "r")) {
    unsigned long long user, nice, system, idle, iowait, irq, softirq;
    if (std::fscanf(f, "cpu %llu %llu %llu %llu %llu %llu %llu", &user, &nice, &system, &idle, &iowait, &irq,
                    &softirq) == 7)
      s.busy_s = double(user + nice + system + irq + softirq) / tick;
    std::fclose(f);
  }
  if (std::FILE* f = std::fopen("/proc/self/stat", "r")) {
    char buf[1024];
    const std::size_t len = std::fread(buf, 1, sizeof buf - 1, f);
    buf[len] = 0;
    std::fclose(f);
    // Fields after the command name (which may hold spaces): state is field 3, utime 14, stime 15, and the
    // waited-for children's cutime 16, cstime 17.
    if (const char* p = std::strrchr(buf, ')')) {
      unsigned long long utime = 0, stime = 0;
      long long cutime = 0, cstime = 0;
      if (std::sscanf(p + 2, "%*c %*d %*d %*d %*d %*d %*u %*u %*u %*u %*u %llu %llu %lld %lld", &utime, &stime,
                      &cutime, &cstime) == 4)
        s.own_s = double(utime + stime + cutime + cstime) / tick;
    }
  }
  return s;
}

double other_cores(const CpuSample& a, const CpuSample& b) {
  const double wall = std::chrono::duration<double>(b.t - a.t).count();
  if (a.busy_s < 0 || a.own_s < 0 || b.busy_s < 0 || b.own_s < 0 || wall <= 0) return -1.0;
  return std::max(0.0, ((b.busy_s - a.busy_s) - (b.own_s - a.own_s)) / wall);
}

LoadAverage load_average() {
  LoadAverage l;
  if (std::FILE* f = std::fopen("/proc/loadavg", "r")) {
    if (std::fscanf(f, "%lf %lf %lf", &l.one, &l.five, &l.fifteen) != 3) l = LoadAverage{};
    std::fclose(f);
  }
  return l;
}

nlohmann::json to_json(const LoadAverage& l) { return nlohmann::json::array({l.one, l.five, l.fifteen}); }

}  // namespace pneumo::bench
