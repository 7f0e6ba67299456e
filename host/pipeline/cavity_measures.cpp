#include "pipeline/cavity_measures.h"

#include <algorithm>
#include <limits>

#include "roles/anatomical_axes.h"

namespace pneumo {

int64_t gas_voxels_anterior_to(const std::vector<uint16_t>& labels, const Geometry& g, uint16_t gas_label,
                               const std::vector<int>& ids, const std::vector<int>& stop_ids) {
  const SliceFrame f = slice_frame(g);
  const std::vector<int64_t> fronts = front_of_labels(labels.data(), f, LabelSet(ids));
  const LabelSet stop(stop_ids);
  int64_t count = 0;
  for (int64_t s = 0; s < f.n_si; ++s)
    for (int64_t l = 0; l < f.n_lat; ++l) {
      const int64_t front = fronts[std::size_t(s * f.n_lat + l)];
      if (front < 0) continue;
      // Forward from the organ's front (anteriority front + 1, …) to the first stop label.
      for (int64_t ant = front + 1; ant < f.n_ap; ++ant) {
        const uint16_t id = labels[std::size_t(f.index(l, f.ant(ant), s))];
        if (stop.contains(id)) break;
        count += id == gas_label;
      }
    }
  return count;
}

double mean_posterior_motion_of_anterior_viscera_mm(const Mesh& m, const std::vector<Vec3>& x) {
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (int64_t n = 0; n < m.node_count(); ++n)
    if (m.node_part[n] == Part::Viscera) {
      lo = std::min(lo, m.rest_m[n].y());
      hi = std::max(hi, m.rest_m[n].y());
    }
  if (!(hi >= lo)) return 0.0;
  const double middle = 0.5 * (lo + hi);
  double sum = 0.0;
  int64_t count = 0;
  for (int64_t n = 0; n < m.node_count(); ++n)
    if (m.node_part[n] == Part::Viscera && m.rest_m[n].y() >= middle) {
      sum += -(x[n].y() - m.rest_m[n].y()) * 1e3;   // m → mm, posterior positive
      ++count;
    }
  return count ? sum / double(count) : 0.0;
}

}  // namespace pneumo
