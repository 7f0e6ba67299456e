#pragma once
// The roles chosen by hand, id by id, for the example CT's TotalSegmentator v2 label map before roles
// came from names (scenes/totalseg_example.json until 2026-12-07; docs/fidelity.md gives each reason):
// what the names must reproduce.
#include <set>
#include <string>
#include <vector>

#include "shared_data.h"

namespace pneumo::testing_support {

inline std::string label_table_dir() { return std::string(PNEUMO_SOURCE_DIR) + "/data/label_tables"; }
inline std::string example_labels_path() { return totalseg_dir() + "/example_seg_fast_force_split.nii.gz"; }
inline std::string example_ct_path() { return totalseg_dir() + "/example_ct.nii.gz"; }

inline const std::vector<int> kHandViscera{1, 4, 5, 6, 18, 20};
inline const std::vector<int> kHandWall{2, 3, 7, 8, 9, 19, 21, 52, 63, 64, 65, 66, 67, 68};
// The lungs (10, 11, 14) were fixed by hand; since the lungs are compliant (roles.compliant_lungs) their
// names make them wall, and kHandLungs lists them apart.
inline const std::vector<int> kHandLungs{10, 11, 14};
inline const std::vector<int> kHandFixed{22, 25, 26, 27, 28, 29, 30, 31, 32, 33, 75, 76, 77, 78, 79, 80, 81,
                                         82, 83, 84, 85, 86, 87, 88, 89, 98, 99, 100, 101, 102, 103, 110, 111, 112, 113,
                                         114, 115, 117};

/// The ids of `ids` that `present` holds, in order.
inline std::vector<int> ids_present(const std::vector<int>& ids, const std::set<int>& present) {
  std::vector<int> out;
  for (int id : ids)
    if (present.count(id)) out.push_back(id);
  return out;
}

}  // namespace pneumo::testing_support
