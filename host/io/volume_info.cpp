#include "io/volume_info.h"

#include <cmath>
#include <sstream>
#include <unordered_map>

namespace pneumo {

namespace {
// Counts distinct integer values, giving up (returns false) past kMaxLabelIds of them.
bool count_labels(const Volume& v, std::map<int64_t, int64_t>* out) {
  std::unordered_map<int64_t, int64_t> counts;
  bool ok = true;
  dispatch_voxel_type(v.type(), const_cast<void*>(v.raw()), [&](auto* p) {
    const int64_t n = v.voxel_count();
    for (int64_t i = 0; i < n && ok; ++i) {
      ++counts[static_cast<int64_t>(p[i])];
      if (counts.size() > static_cast<std::size_t>(kMaxLabelIds)) ok = false;
    }
  });
  if (ok) out->insert(counts.begin(), counts.end());
  return ok;
}
}  // namespace

VolumeInfo describe_volume(const Volume& v) {
  VolumeInfo i;
  i.geometry = v.geometry();
  i.orientation = v.geometry().orientation_code();
  i.datatype = voxel_type_name(v.type());
  const auto r = v.range();
  i.min = r.min;
  i.max = r.max;
  i.nan_count = r.nan_count;
  const Vec3& s = v.geometry().spacing_mm;
  i.voxel_volume_ml = s[0] * s[1] * s[2] * std::abs(v.geometry().direction.determinant()) * 1e-3;
  if (is_integer(v.type())) i.is_label_map = count_labels(v, &i.label_voxels);
  return i;
}

nlohmann::json volume_info_json(const VolumeInfo& i, const std::string& path) {
  const Geometry& g = i.geometry;
  nlohmann::json j;
  j["file"] = path;
  j["dims"] = {g.dims[0], g.dims[1], g.dims[2]};
  j["spacing_mm"] = {g.spacing_mm[0], g.spacing_mm[1], g.spacing_mm[2]};
  j["origin_mm"] = {g.origin_mm[0], g.origin_mm[1], g.origin_mm[2]};
  nlohmann::json dir = nlohmann::json::array();
  for (int r = 0; r < 3; ++r) dir.push_back({g.direction(r, 0), g.direction(r, 1), g.direction(r, 2)});
  j["direction"] = dir;   // rows of the matrix whose columns are the voxel axes in world RAS
  j["world_frame"] = "RAS";
  j["orientation"] = i.orientation;
  j["datatype"] = i.datatype;
  j["min"] = i.min;
  j["max"] = i.max;
  j["nan_voxels"] = i.nan_count;
  j["voxels"] = g.voxel_count();
  j["kind"] = i.is_label_map ? "label_map" : "image";
  if (i.is_label_map) {
    nlohmann::json labels = nlohmann::json::array();
    for (auto [id, n] : i.label_voxels)
      labels.push_back({{"id", id}, {"voxels", n}, {"volume_ml", double(n) * i.voxel_volume_ml}});
    j["labels"] = labels;
  }
  return j;
}

std::string volume_info_text(const VolumeInfo& i, const std::string& path) {
  const Geometry& g = i.geometry;
  std::ostringstream os;
  os.precision(6);
  os << path << "\n";
  os << "  dims         " << g.dims[0] << " x " << g.dims[1] << " x " << g.dims[2] << " (" << g.voxel_count()
     << " voxels)\n";
  os << "  spacing      " << g.spacing_mm[0] << " x " << g.spacing_mm[1] << " x " << g.spacing_mm[2] << " mm\n";
  os << "  origin       (" << g.origin_mm[0] << ", " << g.origin_mm[1] << ", " << g.origin_mm[2] << ") mm, world RAS\n";
  os << "  direction    ";
  for (int r = 0; r < 3; ++r)
    os << (r ? "               " : "") << "[" << g.direction(r, 0) << " " << g.direction(r, 1) << " "
       << g.direction(r, 2) << "]\n";
  os << "  orientation  " << i.orientation << "\n";
  os << "  datatype     " << i.datatype << "\n";
  os << "  range        " << i.min << " .. " << i.max;
  if (i.nan_count) os << " (" << i.nan_count << " NaN voxels)";
  os << "\n";
  if (i.is_label_map) {
    os << "  labels       " << i.label_voxels.size() << " ids\n";
    for (auto [id, n] : i.label_voxels) {
      char line[96];
      std::snprintf(line, sizeof line, "    %6lld  %10lld voxels  %10.1f ml\n", (long long)id, (long long)n,
                    double(n) * i.voxel_volume_ml);
      os << line;
    }
  }
  return os.str();
}

}  // namespace pneumo
