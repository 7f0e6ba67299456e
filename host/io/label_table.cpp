#include "io/label_table.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/input_file.h"

namespace pneumo {

namespace {

// A label table names at most 65,536 labels: a few MB at the very most.
constexpr uint64_t kMaxLabelTableBytes = 16u << 20;

/// The comma-separated fields of one CSV line (no quoting: label names hold none of ",\"").
std::vector<std::string> fields(const std::string& line) {
  std::vector<std::string> out;
  std::stringstream ss(line);
  std::string f;
  while (std::getline(ss, f, ',')) {
    const auto b = f.find_first_not_of(" \t\r"), e = f.find_last_not_of(" \t\r");
    out.push_back(b == std::string::npos ? "" : f.substr(b, e - b + 1));
  }
  const auto last = line.find_last_not_of(" \t\r");
  if (last != std::string::npos && line[last] == ',') out.push_back("");   // getline drops an empty last field
  return out;
}

}  // namespace

std::map<int, std::string> read_label_names(const std::string& path) {
  std::istringstream is(read_input_file(path, kMaxLabelTableBytes, "the label names", "16 MB; a label table is a few kB"));
  std::string line;
  int line_no = 0;
  int id_col = -1, name_col = -1;
  while (std::getline(is, line)) {   // the header: the first line that is not blank
    ++line_no;
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    const std::vector<std::string> h = fields(line);
    for (int c = 0; c < int(h.size()); ++c) {
      if (h[c] == "label_id" || h[c] == "id") id_col = c;
      if (h[c] == "name") name_col = c;
    }
    break;
  }
  if (id_col < 0 || name_col < 0)
    throw file_error(path, "line " + std::to_string(line_no) + ": the header needs a \"label_id\" and a \"name\" column");
  std::map<int, std::string> names;
  while (std::getline(is, line)) {
    ++line_no;
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    const std::vector<std::string> f = fields(line);
    const std::string where = "line " + std::to_string(line_no) + ": ";
    if (int(f.size()) <= std::max(id_col, name_col)) throw file_error(path, where + "fewer columns than the header");
    std::size_t used = 0;
    int id = -1;
    try {
      id = std::stoi(f[id_col], &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used != f[id_col].size() || id < 0 || id > 65535)
      throw file_error(path, where + "label id \"" + f[id_col] + "\" is not an integer in 0...65535");
    if (f[name_col].empty()) throw file_error(path, where + "label " + std::to_string(id) + " has no name");
    if (!names.emplace(id, f[name_col]).second) throw file_error(path, where + "label " + std::to_string(id) + " is named twice");
  }
  return names;
}

void write_slicer_colour_table(const std::string& path, const std::vector<LabelTableEntry>& entries) {
  std::ostringstream os;
  os << "# Color table file " << path.substr(path.find_last_of('/') + 1) << "\n"
     << "# " << entries.size() << " values\n";
  for (const LabelTableEntry& e : entries) {
    std::string name = e.name;
    std::replace(name.begin(), name.end(), ' ', '_');
    os << e.id << " " << name << " " << int(e.rgb[0]) << " " << int(e.rgb[1]) << " " << int(e.rgb[2]) << " "
       << int(std::lround(255.0 * std::clamp(e.opacity, 0.0, 1.0))) << "\n";
  }
  write_text_file_atomic(path, os.str());
}

void write_itksnap_label_description(const std::string& path, const std::vector<LabelTableEntry>& entries) {
  std::ostringstream os;
  os << "################################################\n"
        "# ITK-SnAP Label Description File\n"
        "# File format: \n"
        "# IDX   -R-  -G-  -B-  -A--  VIS MSH  LABEL\n"
        "# Fields: \n"
        "#    IDX:   Zero-based index \n"
        "#    -R-:   Red color component (0..255)\n"
        "#    -G-:   Green color component (0..255)\n"
        "#    -B-:   Blue color component (0..255)\n"
        "#    -A-:   Label transparency (0.00 .. 1.00)\n"
        "#    VIS:   Label visibility (0 or 1)\n"
        "#    MSH:   Label mesh visibility (0 or 1)\n"
        "#  LABEL:   Label description \n"
        "################################################\n";
  for (const LabelTableEntry& e : entries) {
    std::string name = e.name;
    std::replace(name.begin(), name.end(), '"', '\'');
    char line[128];
    const int visible = e.id != 0;
    std::snprintf(line, sizeof line, "%5d %5d %4d %4d %8.2f %2d %2d    ", e.id, int(e.rgb[0]), int(e.rgb[1]),
                  int(e.rgb[2]), std::clamp(e.opacity, 0.0, 1.0), visible, visible);
    os << line << "\"" << name << "\"\n";
  }
  write_text_file_atomic(path, os.str());
}

}  // namespace pneumo
