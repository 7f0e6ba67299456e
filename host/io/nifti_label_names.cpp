// The names a label map carries in its own NIfTI-1 header extension. TotalSegmentator (`--ml`) writes
// them as a Caret-style XML label table in an extension (code 0) after the 348-byte header:
//   <LabelTable> <Label Key="5" Red=… Alpha="1"><![CDATA[liver]]></Label> … </LabelTable>
// so a multi-label map is self-describing and a scene needs no separate names file. Only the bytes
// between the header and the voxels are read (read_nifti_extensions). The table is read with a few string
// searches, not an XML library: pneumo reads one element type whose attributes it needs one of, and
// a malformed table is refused, not repaired.
#include <cstdint>
#include <cstring>
#include <string>

#include "core/error.h"
#include "io/label_table.h"
#include "io/volume_io.h"

namespace pneumo {

namespace {

uint32_t swap32(uint32_t v) { return (v >> 24) | ((v >> 8) & 0xff00u) | ((v << 8) & 0xff0000u) | (v << 24); }

int32_t read_i32(const unsigned char* p, bool swapped) {
  uint32_t v;
  std::memcpy(&v, p, 4);
  return int32_t(swapped ? swap32(v) : v);
}

/// Names from one extension's text; empty when it holds no <LabelTable>.
std::map<int, std::string> names_from_label_table(const std::string& text, const std::string& path) {
  std::map<int, std::string> names;
  if (text.find("<LabelTable") == std::string::npos) return names;
  std::size_t at = 0;
  while ((at = text.find("<Label ", at)) != std::string::npos) {
    const std::size_t open_end = text.find('>', at);
    const std::size_t close = text.find("</Label>", at);
    if (open_end == std::string::npos || close == std::string::npos || close < open_end)
      throw file_error(path, "the label table in the NIfTI header extension is cut short (a <Label> without its end)");
    const std::string attributes = text.substr(at, open_end - at);
    const std::size_t key = attributes.find("Key=\"");
    if (key == std::string::npos)
      throw file_error(path, "a <Label> in the NIfTI header extension has no Key: " + attributes.substr(0, 80));
    const std::size_t key_end = attributes.find('"', key + 5);
    const std::string key_text = attributes.substr(key + 5, key_end == std::string::npos ? 0 : key_end - key - 5);
    int id = -1;
    if (key_text.empty() || key_text.size() > 5 || key_text.find_first_not_of("0123456789") != std::string::npos ||
        (id = std::stoi(key_text)) > 65535)
      throw file_error(path, "a <Label> in the NIfTI header extension has Key \"" + key_text.substr(0, 20) +
                                 "\" (must be a label id 0…65535)");
    std::string name = text.substr(open_end + 1, close - open_end - 1);
    if (name.rfind("<![CDATA[", 0) == 0 && name.size() >= 12 && name.compare(name.size() - 3, 3, "]]>") == 0)
      name = name.substr(9, name.size() - 12);
    const auto b = name.find_first_not_of(" \t\r\n"), e = name.find_last_not_of(" \t\r\n");
    name = b == std::string::npos ? "" : name.substr(b, e - b + 1);
    if (name.empty()) throw file_error(path, "label " + std::to_string(id) + " has an empty name in the NIfTI header extension");
    if (!names.emplace(id, name).second)
      throw file_error(path, "label " + std::to_string(id) + " is named twice in the NIfTI header extension");
    at = close + 8;
  }
  return names;
}

}  // namespace

std::map<int, std::string> read_nifti_label_names(const std::string& path) {
  const NiftiExtensions e = read_nifti_extensions(path);
  const std::string& ext = e.bytes;
  const bool swapped = e.swapped;
  const uint64_t n = ext.size();
  // NIfTI-1 extensions: esize (a multiple of 16, including its 8-byte head), ecode, then the data.
  for (uint64_t at = 0; at + 8 <= n;) {
    const int32_t esize = read_i32(reinterpret_cast<const unsigned char*>(ext.data() + at), swapped);
    if (esize < 8 || uint64_t(esize) > n - at) break;   // the rest is padding, as niftilib reads it
    std::map<int, std::string> names = names_from_label_table(ext.substr(at + 8, uint64_t(esize) - 8), path);
    if (!names.empty()) return names;
    at += uint64_t(esize);
  }
  return {};
}

}  // namespace pneumo
