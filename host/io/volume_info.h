#pragma once
// What `pneumo info` reports about a volume, as data (so tests and reports share it).
#include <map>
#include <nlohmann/json.hpp>
#include <string>

#include "io/volume.h"

namespace pneumo {

struct VolumeInfo {
  Geometry geometry;
  std::string orientation, datatype;
  double min = 0, max = 0;
  int64_t nan_count = 0;
  /// A label map: integer voxels with few distinct values (at most kMaxLabelIds).
  bool is_label_map = false;
  std::map<int64_t, int64_t> label_voxels;   // id → voxel count (label maps only)
  double voxel_volume_ml = 0;
};

constexpr int kMaxLabelIds = 512;

VolumeInfo describe_volume(const Volume& v);
nlohmann::json volume_info_json(const VolumeInfo& info, const std::string& path);
std::string volume_info_text(const VolumeInfo& info, const std::string& path);

}  // namespace pneumo
