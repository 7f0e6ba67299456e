#pragma once
// A set of label ids (a scene's list of TotalSegmentator or phantom ids) as a table over every
// uint16 id, so that the voxel loops that ask "is this voxel's label listed?" do one load per voxel.
// Ids outside 0…65535 cannot occur in a label map and are left out (the scene refuses them).
#include <cstdint>
#include <vector>

namespace pneumo {

class LabelSet {
 public:
  LabelSet() = default;
  explicit LabelSet(const std::vector<int>& ids) {
    for (const int id : ids) {
      if (id < 0 || id > 65535) continue;
      if (listed_.empty()) listed_.assign(65536, 0);
      listed_[std::size_t(id)] = 1;
    }
  }
  bool empty() const { return listed_.empty(); }
  bool contains(uint16_t id) const { return !listed_.empty() && listed_[id] != 0; }

 private:
  std::vector<uint8_t> listed_;   // by id; empty when no id is listed
};

}  // namespace pneumo
