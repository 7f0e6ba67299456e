#pragma once
// `pneumo bench`'s JSON as Markdown tables, and the speed–accuracy plot (SVG, written beside the Markdown with the
// same name and .svg): time against error, one curve per solver, the Pareto front marked.
#include <string>

#include <nlohmann/json.hpp>

namespace pneumo::bench {

std::string bench_markdown(const nlohmann::json& doc, const std::string& plot_file_name);
std::string speed_accuracy_svg(const nlohmann::json& speed_accuracy);

/// Writes `path` and the plot beside it (path with .md replaced by .svg), each atomically.
void write_bench_markdown(const nlohmann::json& doc, const std::string& path);

}  // namespace pneumo::bench
