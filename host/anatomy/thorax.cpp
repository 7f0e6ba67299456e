#include "anatomy/thorax.h"

#include <algorithm>
#include <cmath>

#include "anatomy/anatomical_axes.h"
#include "anatomy/distance_transform.h"

namespace pneumo {

namespace {

/// Aerated parts of the body that are lung (thorax.h): each 6-connected part of `aerated` is walked
/// once (breadth first, its voxels listed), and kept where its size and median HU say lung.
int mark_lungs_by_density(const float* hu, std::vector<uint8_t>& aerated, const Geometry& g,
                          const ThoraxOptions& opt, std::vector<uint8_t>& lungs) {
  const Index3 d = g.dims;
  const int64_t stride[3] = {1, d[0], d[0] * d[1]};
  const double voxel_ml = g.spacing_mm.prod() / 1000.0;
  int parts = 0;
  std::vector<int64_t> part;
  std::vector<float> values;
  for (int64_t seed = 0; seed < int64_t(aerated.size()); ++seed) {
    if (aerated[seed] != 1) continue;
    part.assign(1, seed);
    aerated[seed] = 2;
    for (std::size_t q = 0; q < part.size(); ++q) {
      const int64_t v = part[q];
      const int64_t ijk[3] = {v % d[0], (v / d[0]) % d[1], v / (d[0] * d[1])};
      for (int a = 0; a < 3; ++a)
        for (int side = -1; side <= 1; side += 2) {
          const int64_t c = ijk[a] + side;
          if (c < 0 || c >= d[a]) continue;
          const int64_t w = v + side * stride[a];
          if (aerated[w] == 1) {
            aerated[w] = 2;
            part.push_back(w);
          }
        }
    }
    if (double(part.size()) * voxel_ml < opt.min_lung_ml) continue;
    values.resize(part.size());
    for (std::size_t k = 0; k < part.size(); ++k) values[k] = hu[part[k]];
    std::nth_element(values.begin(), values.begin() + values.size() / 2, values.end());
    const double median = values[values.size() / 2];
    if (median < opt.lung_median_min_hu || median > opt.lung_median_max_hu) continue;
    ++parts;
    for (int64_t v : part) lungs[v] = 1;
  }
  return parts;
}

/// `base` (per column, -1 where none) with each gap between two columns that have a value filled in
/// linearly, along lines of `n` columns `step` apart; `lines` such lines, `line_step` apart.
std::vector<double> fill_gaps(const std::vector<double>& base, int64_t n, int64_t lines, int64_t step,
                              int64_t line_step) {
  std::vector<double> out = base;
  for (int64_t line = 0; line < lines; ++line) {
    auto at = [&](int64_t k) -> double& { return out[std::size_t(line * line_step + k * step)]; };
    int64_t last = -1;
    for (int64_t k = 0; k < n; ++k) {
      if (base[std::size_t(line * line_step + k * step)] < 0.0) continue;
      if (last >= 0 && k - last > 1)
        for (int64_t m = last + 1; m < k; ++m) at(m) = at(last) + (at(k) - at(last)) * double(m - last) / double(k - last);
      last = k;
    }
  }
  return out;
}

/// The morphological closing of `lung` by a ball of radius r_mm: every voxel whose r-neighbourhood
/// lies inside the lung's r-dilation (the dilation's complement is more than r away). Fills the
/// vessels and bronchi a lung holds; two exact distance transforms.
std::vector<uint8_t> closing(const std::vector<uint8_t>& lung, const Geometry& g, double r_mm) {
  const int64_t n = int64_t(lung.size());
  std::vector<uint8_t> mask(lung.size());
#pragma omp parallel for schedule(static)
  for (int64_t v = 0; v < n; ++v) mask[v] = !lung[v];
  const std::vector<float> to_lung = distance_to_outside_mm(mask, g);
  const float r = float(r_mm);
#pragma omp parallel for schedule(static)
  for (int64_t v = 0; v < n; ++v) mask[v] = to_lung[v] <= r;
  const std::vector<float> to_outside = distance_to_outside_mm(mask, g);
#pragma omp parallel for schedule(static)
  for (int64_t v = 0; v < n; ++v) mask[v] = lung[v] || to_outside[v] > r;
  return mask;
}

}  // namespace

Thorax find_thorax(const float* hu, const std::vector<uint8_t>& body, const Geometry& g,
                   const std::vector<uint8_t>* labelled, const ThoraxOptions& opt) {
  const int64_t n = g.voxel_count();
  Thorax t;
  t.lungs.assign(std::size_t(n), 0);
  t.chest.assign(std::size_t(n), 0);
  {
    std::vector<uint8_t> aerated(static_cast<std::size_t>(n));
    const float below = float(opt.aerated_hu);
#pragma omp parallel for schedule(static)
    for (int64_t v = 0; v < n; ++v) aerated[v] = body[v] && hu[v] < below;
    t.lung_parts = mark_lungs_by_density(hu, aerated, g, opt, t.lungs);
  }
  const bool with_labels = labelled && int64_t(labelled->size()) == n;
  if (with_labels)
    for (int64_t v = 0; v < n; ++v) t.lungs[v] |= (*labelled)[v] && body[v];
  const auto labelled_heart = [&](int64_t v) { return with_labels && (*labelled)[v] == 2; };

  // The diaphragm's upper surface per column: the lowest lung voxel, as a superior index (0 = the
  // most inferior slice), -1 where the column holds no lung.
  const SliceFrame f = slice_frame(g);
  const int up = anatomical_axes(g).sign[2];
  auto sup = [&](int64_t s) { return up > 0 ? s : f.n_si - 1 - s; };
  std::vector<double> base(std::size_t(f.n_lat * f.n_ap), -1.0);
  for (int64_t s = 0; s < f.n_si; ++s)
    for (int64_t a = 0; a < f.n_ap; ++a)
      for (int64_t l = 0; l < f.n_lat; ++l) {
        if (!t.lungs[f.index(l, a, s)]) continue;
        double& b = base[std::size_t(a * f.n_lat + l)];
        if (b < 0.0 || double(sup(s)) < b) b = double(sup(s));
      }
  // Where a column holds no lung (the heart and mediastinum between the lungs, in front of them or
  // behind), the surface is interpolated linearly between the nearest lung columns on either side,
  // along the lateral row and along the antero-posterior line, and the lower of the two is taken:
  // a lung that reaches around the heart in one direction and not the other still bounds it.
  const std::vector<double> across = fill_gaps(base, f.n_lat, f.n_ap, 1, f.n_lat);
  const std::vector<double> along = fill_gaps(base, f.n_ap, f.n_lat, f.n_lat, 1);
  for (std::size_t c = 0; c < base.size(); ++c) {
    if (base[c] >= 0.0) continue;
    const double x = across[c], y = along[c];
    base[c] = x >= 0.0 && y >= 0.0 ? std::min(x, y) : std::max(x, y);
  }
  int64_t chest = 0, lungs = 0;
#pragma omp parallel for schedule(static) reduction(+ : chest, lungs)
  for (int64_t s = 0; s < f.n_si; ++s)
    for (int64_t a = 0; a < f.n_ap; ++a)
      for (int64_t l = 0; l < f.n_lat; ++l) {
        const int64_t v = f.index(l, a, s);
        const double b = base[std::size_t(a * f.n_lat + l)];
        t.chest[v] = body[v] && b >= 0.0 && double(sup(s)) >= std::ceil(b - 1e-9);
        t.chest[v] |= t.lungs[v];
        chest += t.chest[v];
        lungs += t.lungs[v];
      }
  if (opt.lung_closing_mm > 0.0) {
    std::vector<uint8_t> lung_only(t.lungs.size());   // density and labelled lung, not the heart
#pragma omp parallel for schedule(static)
    for (int64_t v = 0; v < n; ++v) lung_only[v] = t.lungs[v] && !labelled_heart(v);
    t.lung_tissue = closing(lung_only, g, opt.lung_closing_mm);
#pragma omp parallel for schedule(static)
    for (int64_t v = 0; v < n; ++v) t.lung_tissue[v] = t.lung_tissue[v] && t.chest[v] && !labelled_heart(v);
  }
  const double voxel_ml = g.spacing_mm.prod() / 1000.0;
  t.chest_ml = double(chest) * voxel_ml;
  t.lung_ml = double(lungs) * voxel_ml;
  return t;
}

}  // namespace pneumo
