#include "cli/unknown_subcommand.h"

#include <algorithm>
#include <numeric>

namespace pneumo::cli {
namespace {

// Levenshtein distance (insertions, deletions, substitutions), one row at a time.
std::size_t edit_distance(const std::string& a, const std::string& b) {
  std::vector<std::size_t> row(b.size() + 1);
  std::iota(row.begin(), row.end(), std::size_t{0});
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diagonal = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t up = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] != b[j - 1])});
      diagonal = up;
    }
  }
  return row[b.size()];
}

}  // namespace

std::string unknown_subcommand_message(const std::vector<std::string>& args,
                                       const std::vector<std::string>& value_options,
                                       const std::vector<std::string>& subcommands) {
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    if (a.empty()) continue;
    if (a[0] == '-') {
      if (std::find(value_options.begin(), value_options.end(), a) != value_options.end()) ++i;  // its value
      continue;
    }
    if (std::find(subcommands.begin(), subcommands.end(), a) != subcommands.end()) return "";
    // A typo is at most a third of the word away (two letters in "simulate"), or the word begins one.
    std::string closest;
    std::size_t best = a.size() / 3 + 1;
    for (const std::string& s : subcommands) {
      const std::size_t d = s.rfind(a, 0) == 0 ? 0 : edit_distance(a, s);
      if (d < best) best = d, closest = s;
    }
    std::string msg = "unknown subcommand '" + a + "'";
    if (!closest.empty()) msg += " (did you mean '" + closest + "'?)";
    msg += "; the subcommands are";
    for (std::size_t k = 0; k < subcommands.size(); ++k) msg += (k ? ", " : " ") + subcommands[k];
    return msg + " (pneumo --help describes them)";
  }
  return "";
}

}  // namespace pneumo::cli
