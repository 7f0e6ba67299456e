#include "pipeline/cavity_measures.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "anatomy/anatomical_axes.h"

namespace pneumo {

namespace {

/// Column (l, s) of `f` forward from anteriority `front` + 1 to the first stop label: its gas
/// voxels, and the anteriority of the first of them (-1: none).
struct GasInFront {
  int64_t voxels = 0;
  int64_t first = -1;
};
GasInFront gas_in_front(const std::vector<uint16_t>& labels, const SliceFrame& f, int64_t l, int64_t s, int64_t front,
                        uint16_t gas_label, const LabelSet& stop) {
  GasInFront gas;
  for (int64_t ant = front + 1; ant < f.n_ap; ++ant) {
    const uint16_t id = labels[std::size_t(f.index(l, f.ant(ant), s))];
    if (stop.contains(id)) break;
    if (id != gas_label) continue;
    if (gas.first < 0) gas.first = ant;
    ++gas.voxels;
  }
  return gas;
}

/// Whether a voxel of `organs` lies within one voxel (its 3 × 3 × 3 block) of the rest voxel
/// nearest `rest_mm`: the tolerance of rounding a traced point to a voxel, plus the face it shares.
bool touched_an_organ_at_rest(const RestColumns& rest, const Vec3& rest_mm, const LabelSet& organs) {
  const Vec3 ijk = rest.grid.to_index(rest_mm);
  Index3 v;
  for (int a = 0; a < 3; ++a) v[a] = int64_t(std::llround(ijk[a]));
  for (int64_t dk = -1; dk <= 1; ++dk)
    for (int64_t dj = -1; dj <= 1; ++dj)
      for (int64_t di = -1; di <= 1; ++di) {
        const Index3 n{v[0] + di, v[1] + dj, v[2] + dk};
        if (n[0] < 0 || n[1] < 0 || n[2] < 0 || n[0] >= rest.grid.dims[0] || n[1] >= rest.grid.dims[1] ||
            n[2] >= rest.grid.dims[2])
          continue;
        if (organs.contains(rest.labels[std::size_t(rest.grid.linear_index(n[0], n[1], n[2]))])) return true;
      }
  return false;
}

}  // namespace

int64_t gas_voxels_anterior_to(const std::vector<uint16_t>& labels, const Geometry& g, uint16_t gas_label,
                               const std::vector<int>& ids, const std::vector<int>& stop_ids,
                               const RestColumns* rest) {
  const SliceFrame f = slice_frame(g);
  const std::vector<int64_t> fronts = front_of_labels(labels.data(), f, LabelSet(ids));
  const LabelSet stop(stop_ids);
  int64_t count = 0;
  for (int64_t s = 0; s < f.n_si; ++s)
    for (int64_t l = 0; l < f.n_lat; ++l) {
      const int64_t front = fronts[std::size_t(s * f.n_lat + l)];
      if (front < 0) continue;
      const GasInFront gas = gas_in_front(labels, f, l, s, front, gas_label, stop);
      if (gas.voxels == 0) continue;
      if (rest && rest->to_rest && rest->labels) {
        // The floor: the voxel behind the column's first gas voxel (tissue, or the organ itself).
        int64_t along[3];
        along[f.lat] = l;
        along[f.ap] = f.ant(gas.first - 1);
        along[f.si] = s;
        const std::optional<Vec3> floor_at_rest =
            rest->to_rest(g.to_world(Vec3(double(along[0]), double(along[1]), double(along[2]))));
        if (floor_at_rest && touched_an_organ_at_rest(*rest, *floor_at_rest, stop)) continue;
      }
      count += gas.voxels;
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
