#include "pipeline/organ_motion.h"

#include <array>

#include "domain/label_set.h"

namespace pneumo {

namespace {

struct Sums {
  int64_t count = 0;
  Vec3 index_sum = Vec3::Zero();   // voxel indices summed: the centroid goes to world once, at the end
};

/// Per label: voxel count and the sum of its voxel indices.
std::vector<Sums> sums_of(const std::vector<uint16_t>& labels, const Geometry& g) {
  std::vector<Sums> s(65536);
  for (int64_t k = 0; k < g.dims[2]; ++k)
    for (int64_t j = 0; j < g.dims[1]; ++j)
      for (int64_t i = 0; i < g.dims[0]; ++i) {
        Sums& t = s[labels[std::size_t(g.linear_index(i, j, k))]];
        ++t.count;
        t.index_sum += Vec3(double(i), double(j), double(k));
      }
  return s;
}

}  // namespace

std::vector<OrganMotion> organ_motion(const std::vector<uint16_t>& rest, const Geometry& rest_grid,
                                      const std::vector<uint16_t>& deformed, const Geometry& deformed_grid,
                                      uint16_t skip, const std::map<int, std::string>& names,
                                      const std::vector<int>& ids, double min_ml, const JacobianAtFn& jacobian) {
  std::vector<OrganMotion> out;
  if (int64_t(rest.size()) != rest_grid.voxel_count() || int64_t(deformed.size()) != deformed_grid.voxel_count())
    return out;
  if (ids.empty()) return out;
  const LabelSet wanted(ids);
  const std::vector<Sums> before = sums_of(rest, rest_grid), after = sums_of(deformed, deformed_grid);
  const double ml_before = rest_grid.spacing_mm.prod() / 1000.0, ml_after = deformed_grid.spacing_mm.prod() / 1000.0;
  for (int id = 1; id < 65536; ++id) {
    const Sums& b = before[std::size_t(id)];
    if (id == skip || !wanted.contains(id) || double(b.count) * ml_before < min_ml) continue;
    const Sums& a = after[std::size_t(id)];
    OrganMotion m;
    m.label = id;
    if (const auto it = names.find(id); it != names.end()) m.name = it->second;
    m.volume_ml = double(b.count) * ml_before;
    m.volume_change = double(a.count) * ml_after / m.volume_ml - 1.0;
    if (a.count > 0)
      m.shift_mm = deformed_grid.to_world(a.index_sum / double(a.count)) - rest_grid.to_world(b.index_sum / double(b.count));
    out.push_back(m);
  }
  if (!jacobian || out.empty()) return out;
  std::vector<int> slot(65536, -1);
  for (std::size_t o = 0; o < out.size(); ++o) slot[std::size_t(out[o].label)] = int(o);
  std::vector<double> sum_j_minus_1(out.size(), 0.0);
  for (int64_t k = 0; k < rest_grid.dims[2]; ++k)
    for (int64_t j = 0; j < rest_grid.dims[1]; ++j)
      for (int64_t i = 0; i < rest_grid.dims[0]; ++i) {
        const int64_t v = rest_grid.linear_index(i, j, k);
        const int o = slot[rest[std::size_t(v)]];
        if (o < 0) continue;
        if (const std::optional<double> J = jacobian(v, rest_grid.to_world(Vec3(double(i), double(j), double(k)))))
          sum_j_minus_1[std::size_t(o)] += *J - 1.0;
      }
  for (std::size_t o = 0; o < out.size(); ++o)
    out[o].tissue_volume_change = sum_j_minus_1[o] * ml_before / out[o].volume_ml;
  return out;
}

}  // namespace pneumo
