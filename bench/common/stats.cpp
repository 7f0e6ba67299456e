#include "common/stats.h"

#include <algorithm>

namespace pneumo::bench {

Summary summarize(std::vector<double> samples) {
  Summary s;
  s.n = int(samples.size());
  if (samples.empty()) return s;
  std::sort(samples.begin(), samples.end());
  const std::size_t h = samples.size() / 2;
  s.median = samples.size() % 2 ? samples[h] : 0.5 * (samples[h - 1] + samples[h]);
  s.min = samples.front();
  s.max = samples.back();
  return s;
}

nlohmann::json to_json(const Summary& s) {
  return {{"median", s.median}, {"min", s.min}, {"max", s.max}, {"n", s.n}};
}

}  // namespace pneumo::bench
