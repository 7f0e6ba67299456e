#pragma once
// Medians over repetitions with their spread: how every figure of `pneumo bench` is reported.
#include <vector>

#include <nlohmann/json.hpp>

namespace pneumo::bench {

struct Summary {
  double median = 0.0, min = 0.0, max = 0.0;
  int n = 0;
};

/// Median (the mean of the middle two for an even count), minimum and maximum; n = 0 for none.
Summary summarize(std::vector<double> samples);

/// {"median": …, "min": …, "max": …, "n": …}
nlohmann::json to_json(const Summary& s);

}  // namespace pneumo::bench
