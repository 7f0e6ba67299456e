#pragma once
// Label names in and label tables out. In: a CSV naming label ids (TotalSegmentator's classes,
// data/label_tables/, or a case's own). Out: the colour table 3D Slicer loads beside a label map
// (.ctbl: "id name R G B A", 0-255) and ITK-SNAP's label description file (index, RGB, opacity,
// visibility, mesh visibility, quoted name), so the deformed labels open with their names.
#include <array>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

namespace pneumo {

/// Reads `path`: a header row with a column "label_id" (or "id") and a column "name", then one row
/// per id; other columns are ignored. InputError naming the file and line for a missing column, an
/// id outside 0…65535, an id given twice or an empty name.
std::map<int, std::string> read_label_names(const std::string& path);

/// The names a NIfTI-1 label map carries in its header extension (TotalSegmentator's `--ml` output:
/// a Caret XML <LabelTable>), read without its voxels; empty when it carries none or is not NIfTI-1.
/// InputError naming the file for a malformed table (a Key that is not an id, a name given twice).
std::map<int, std::string> read_nifti_label_names(const std::string& path);

struct LabelTableEntry {
  int id = 0;
  std::string name;
  std::array<uint8_t, 3> rgb{0, 0, 0};
  double opacity = 1.0;   // 0…1
};

/// 3D Slicer's colour table: one "id name R G B A" line per entry (spaces in names become '_',
/// which Slicer's format cannot hold). Written atomically.
void write_slicer_colour_table(const std::string& path, const std::vector<LabelTableEntry>& entries);
/// ITK-SNAP's label description file (its "Export label descriptions" format). Written atomically.
void write_itksnap_label_description(const std::string& path, const std::vector<LabelTableEntry>& entries);

}  // namespace pneumo
