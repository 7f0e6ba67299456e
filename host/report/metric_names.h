#pragma once
// What the report calls each key of metrics.json: a name a reader understands, its unit, and the
// group it is shown in. Keys without an entry are named from the key itself, the unit from its
// suffix (_mm, _ml, _mmhg, _s, _ms, _fraction ...), so a new metric never shows as a raw key.
#include <string>
#include <vector>

namespace pneumo {

struct MetricName {
  std::string name;    // "Anterior rise"
  std::string unit;    // "mm"; empty when dimensionless
  std::string group;   // "Result", "Solver", "Model", "Warp", "Other"
  double scale = 1.0;  // shown value = stored value × scale (a fraction as %)
};

/// The name of `key` (a top-level key, or "parent.child" for a nested one).
MetricName metric_name(const std::string& key);

/// The name of `column` in the table of the array `array_key` (an array of objects, such as
/// pressure_curve): its entry as "array_key.column" where it has one, else the column's own.
MetricName column_name(const std::string& array_key, const std::string& column);

/// Every key with an entry of its own (not named from its suffix), in the order the table lists
/// them, "parent.child" for nested ones: a test builds a metrics.json of them all and reads each back.
std::vector<std::string> listed_metric_keys();

/// The report's groups, in the order shown.
const std::vector<std::string>& metric_groups();

/// The pipeline's stages in the order they run (stage_seconds' keys), "total" last.
const std::vector<std::string>& pipeline_stage_order();

}  // namespace pneumo
