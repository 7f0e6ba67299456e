#include "render/render_volume.h"

#include <algorithm>
#include <cmath>
#include <deque>
#include <stdexcept>
#include <string>

#include "core/error.h"
#include "render/transfer_function.h"

namespace pneumo {

namespace {

[[noreturn]] void refuse_label_value(double value) {
  throw InputError("label map value " + std::to_string(value) + " is not an id from 0 to 65534");
}

}  // namespace

RenderVolume RenderVolume::from(const Volume& ct, const Volume* labels) {
  return from_hu(ct.geometry(), ct.to_float32(), labels);
}

RenderVolume RenderVolume::from_hu(const Geometry& g, std::vector<float>&& hu, const Volume* labels) {
  const int64_t n = int64_t(hu.size());
  bool all_int16 = true;
#pragma omp parallel for schedule(static) reduction(&& : all_int16)
  for (int64_t i = 0; i < n; ++i) all_int16 = all_int16 && fits_int16_texture(hu[std::size_t(i)]);
  return from_hu(g, std::move(hu), labels, all_int16);
}

RenderVolume RenderVolume::from_hu(const Geometry& g, std::vector<float>&& hu, const Volume* labels,
                                   bool hu_is_int16) {
  if (int64_t(hu.size()) != g.voxel_count())
    throw std::invalid_argument("RenderVolume::from_hu: " + std::to_string(hu.size()) + " values for " +
                                std::to_string(g.voxel_count()) + " voxels");
  RenderVolume v;
  v.geometry = g;
  v.hu_is_int16 = hu_is_int16;
  const int64_t n = g.voxel_count();
  if (labels) {
    if (!labels->geometry().same_grid(g, 1e-3))
      throw InputError("the label map's voxel grid differs from the CT's; the renderer needs them on one grid");
    v.labels.resize(std::size_t(n));
    // Typed, not through Volume::value: a 0.75 mm CT has 10⁸ voxels. The first bad voxel (lowest
    // index) is the one reported, whatever the thread count.
    int64_t first_bad = n;
    dispatch_voxel_type(labels->type(), const_cast<void*>(labels->raw()), [&](auto* p) {
#pragma omp parallel for schedule(static) reduction(min : first_bad)
      for (int64_t i = 0; i < n; ++i) {
        const double id = double(p[i]);
        if (!(id >= 0 && id < kExteriorAirLabel) || id != std::floor(id)) first_bad = std::min(first_bad, i);
        else v.labels[std::size_t(i)] = static_cast<uint16_t>(id);
      }
    });
    if (first_bad < n) refuse_label_value(labels->value(first_bad));
  }
  v.hu = std::move(hu);   // last: a refused label map leaves the caller's values with it
  return v;
}

RenderVolume RenderVolume::from_hu(const Geometry& g, std::vector<float>&& hu, std::vector<uint16_t>&& labels,
                                   bool hu_is_int16) {
  const int64_t n = int64_t(labels.size());
  if (n != 0 && n != g.voxel_count())
    throw std::invalid_argument("RenderVolume::from_hu: " + std::to_string(n) + " labels for " +
                                std::to_string(g.voxel_count()) + " voxels");
  int reserved = 0;
#pragma omp parallel for schedule(static) reduction(| : reserved)
  for (int64_t i = 0; i < n; ++i) reserved |= labels[std::size_t(i)] == kExteriorAirLabel;
  if (reserved) refuse_label_value(kExteriorAirLabel);
  RenderVolume v = from_hu(g, std::move(hu), nullptr, hu_is_int16);
  v.labels = std::move(labels);
  return v;
}

void RenderVolume::mark_exterior_air(double threshold_hu) {
  const auto& d = geometry.dims;
  if (labels.empty()) labels.assign(hu.size(), 0);
  std::vector<uint8_t> seen(hu.size(), 0);
  std::deque<int64_t> queue;
  auto push = [&](int64_t i, int64_t j, int64_t k) {
    const int64_t n = geometry.linear_index(i, j, k);
    if (seen[n] || !(hu[n] <= threshold_hu)) return;
    seen[n] = 1;
    queue.push_back(n);
  };
  for (int64_t k = 0; k < d[2]; ++k)
    for (int64_t j = 0; j < d[1]; ++j)
      for (int64_t i = 0; i < d[0]; ++i)
        if (i == 0 || j == 0 || k == 0 || i == d[0] - 1 || j == d[1] - 1 || k == d[2] - 1) push(i, j, k);
  while (!queue.empty()) {
    const int64_t n = queue.front();
    queue.pop_front();
    labels[n] = kExteriorAirLabel;
    const int64_t i = n % d[0], j = (n / d[0]) % d[1], k = n / (d[0] * d[1]);
    if (i > 0) push(i - 1, j, k);
    if (i + 1 < d[0]) push(i + 1, j, k);
    if (j > 0) push(i, j - 1, k);
    if (j + 1 < d[1]) push(i, j + 1, k);
    if (k > 0) push(i, j, k - 1);
    if (k + 1 < d[2]) push(i, j, k + 1);
  }
}

Vec3 view_smoothing_sigma_voxels(const Geometry& g, double smoothing_mm) {
  if (!(smoothing_mm > 0.0)) return Vec3::Zero();
  Vec3 s;
  for (int a = 0; a < 3; ++a) s[a] = std::max(1.0, smoothing_mm / g.spacing_mm[a]);
  return s;
}

namespace {

// Taps of a Gaussian of σ voxels truncated at ⌈3σ⌉ and renormalised.
std::vector<float> gaussian_taps(double sigma) {
  const int radius = std::max(1, int(std::ceil(3.0 * sigma)));
  std::vector<double> w(std::size_t(2 * radius + 1));
  double sum = 0.0;
  for (int r = -radius; r <= radius; ++r) sum += w[std::size_t(r + radius)] = std::exp(-0.5 * r * r / (sigma * sigma));
  std::vector<float> f(w.size());
  for (std::size_t i = 0; i < w.size(); ++i) f[i] = float(w[i] / sum);
  return f;
}

// out[row] = Σ_r w[r]·in_row(r): rows of `n` floats, summed tap by tap so the inner loop runs along
// the row (vectorised, streaming).
inline void weighted_rows(float* out, const std::vector<const float*>& rows, const std::vector<float>& w, int64_t n) {
  std::fill(out, out + n, 0.0f);
  for (std::size_t r = 0; r < w.size(); ++r) {
    const float* in = rows[r];
    const float wr = w[r];
    for (int64_t i = 0; i < n; ++i) out[i] += wr * in[i];
  }
}

// The three passes of the views' prefilter, each laid out so that its inner loop runs along
// contiguous memory: along i a padded copy of the row, along j and k whole rows weighted and summed
// (k innermost per j, so the rows a tap reuses stay in cache). Each pass keeps only every
// stride[a]-th output along its axis, so a decimated result costs a fraction of a full one: with
// stride 2 the passes write n/2, n/4 and n/8 values instead of 3n. Every kept value is summed in
// the same order as with stride 1 (and -ffp-contract=off forbids fused multiply-adds), so it equals
// the full-resolution result at that voxel bit for bit.
std::vector<float> gaussian_filter(const float* src, const Index3& d, const Vec3& sigma, const Index3& stride) {
  const int64_t nx = d[0], ny = d[1], nz = d[2];
  const int64_t mx = (nx - 1) / stride[0] + 1, my = (ny - 1) / stride[1] + 1, mz = (nz - 1) / stride[2] + 1;
  std::vector<float> along_i(std::size_t(mx * ny * nz));
  {  // along i: src → along_i (mx per row)
    const std::vector<float> w = gaussian_taps(sigma[0]);
    const int64_t R = int64_t(w.size() / 2), f = stride[0];
    // With stride f the padded line is dealt into f phases, phase p holding line[f·m + p]: output i
    // then reads tap r at phase r mod f, index i + r div f, so every tap is a contiguous row again
    // and the kept outputs go through weighted_rows like the full-resolution ones.
    const int64_t padded = nx + 2 * R, phase_length = (padded + f - 1) / f;
#pragma omp parallel
    {
      std::vector<float> line(static_cast<std::size_t>(padded));
      std::vector<float> phases(f == 1 ? 0 : std::size_t(f * phase_length));
      std::vector<const float*> rows(w.size());
      if (f == 1)
        for (std::size_t r = 0; r < w.size(); ++r) rows[r] = line.data() + r;
      else
        for (std::size_t r = 0; r < w.size(); ++r)
          rows[r] = phases.data() + (int64_t(r) % f) * phase_length + int64_t(r) / f;
#pragma omp for schedule(static)
      for (int64_t q = 0; q < ny * nz; ++q) {
        const float* in = src + q * nx;
        for (int64_t t = -R; t < nx + R; ++t) line[std::size_t(t + R)] = in[std::clamp<int64_t>(t, 0, nx - 1)];
        for (int64_t p = 0; f > 1 && p < f; ++p) {
          float* phase = phases.data() + p * phase_length;
          for (int64_t m = 0, t = p; t < padded; ++m, t += f) phase[m] = line[std::size_t(t)];
        }
        weighted_rows(along_i.data() + q * mx, rows, w, mx);
      }
    }
  }
  std::vector<float> along_j(std::size_t(mx * my * nz));
  {  // along j: along_i → along_j (rows of mx, my per slice)
    const std::vector<float> w = gaussian_taps(sigma[1]);
    const int64_t R = int64_t(w.size() / 2), f = stride[1];
#pragma omp parallel
    {
      std::vector<const float*> rows(w.size());
#pragma omp for schedule(static)
      for (int64_t q = 0; q < my * nz; ++q) {
        const int64_t j = (q % my) * f, k = q / my;
        for (int64_t r = 0; r < int64_t(w.size()); ++r)
          rows[std::size_t(r)] = along_i.data() + (k * ny + std::clamp<int64_t>(j + r - R, 0, ny - 1)) * mx;
        weighted_rows(along_j.data() + q * mx, rows, w, mx);
      }
    }
  }
  // along k: along_j → the result; at stride 1 into along_i's memory, which no one reads any more.
  std::vector<float> result;
  if (stride[0] == 1 && stride[1] == 1 && stride[2] == 1) result.swap(along_i);
  else result.resize(std::size_t(mx * my * mz));
  {
    const std::vector<float> w = gaussian_taps(sigma[2]);
    const int64_t R = int64_t(w.size() / 2), f = stride[2];
#pragma omp parallel
    {
      std::vector<const float*> rows(w.size());
#pragma omp for schedule(static)
      for (int64_t j = 0; j < my; ++j)
        for (int64_t k = 0; k < mz; ++k) {
          for (int64_t r = 0; r < int64_t(w.size()); ++r)
            rows[std::size_t(r)] = along_j.data() + (std::clamp<int64_t>(f * k + r - R, 0, nz - 1) * my + j) * mx;
          weighted_rows(result.data() + (k * my + j) * mx, rows, w, mx);
        }
    }
  }
  return result;
}

// Whole HU, as a 16-bit texture holds them (hu_is_int16).
void round_to_int16_hu(std::vector<float>& hu) {
  float* h = hu.data();
  const int64_t n = int64_t(hu.size());
#pragma omp parallel for schedule(static)
  for (int64_t i = 0; i < n; ++i) h[i] = std::nearbyint(std::clamp(h[i], -32767.0f, 32767.0f));
}

}  // namespace

void smooth_for_views(RenderVolume& v, const Vec3& sigma_voxels) {
  if (!(sigma_voxels.minCoeff() > 0.0) || v.hu.empty()) return;
  v.hu = gaussian_filter(v.hu.data(), v.geometry.dims, sigma_voxels, Index3{1, 1, 1});
  if (v.hu_is_int16) round_to_int16_hu(v.hu);
}

Index3 view_grid_stride(const Geometry& g, double smoothing_mm) {
  const Vec3 sigma = view_smoothing_sigma_voxels(g, smoothing_mm);
  Index3 f{1, 1, 1};
  for (int a = 0; a < 3; ++a) f[a] = std::max<int64_t>(1, int64_t(std::floor(sigma[a] + 1e-9)));
  return f;
}

Geometry view_grid(const Geometry& g, const Index3& stride) {
  Geometry c = g;
  for (int a = 0; a < 3; ++a) {
    c.dims[a] = (g.dims[a] - 1) / stride[a] + 1;
    c.spacing_mm[a] = g.spacing_mm[a] * double(stride[a]);
  }
  return c;   // voxel (0,0,0) stays where it was: origin and direction unchanged
}

const RenderVolume& volume_as_viewed(const RenderVolume& v, std::optional<RenderVolume>& storage, bool with_labels) {
  if (!(v.smoothing_mm > 0.0)) return v;
  const Index3 stride = v.views_on_ct_grid ? Index3{1, 1, 1} : view_grid_stride(v.geometry, v.smoothing_mm);
  const bool resampled = stride != Index3{1, 1, 1};
  storage.emplace();
  storage->geometry = view_grid(v.geometry, stride);
  storage->hu_is_int16 = v.hu_is_int16;
  storage->hu = gaussian_filter(v.hu.data(), v.geometry.dims, view_smoothing_sigma_voxels(v.geometry, v.smoothing_mm),
                                stride);
  if (v.hu_is_int16) round_to_int16_hu(storage->hu);
  if (resampled && !v.labels.empty()) {  // the label at each kept voxel: nearest, as the casters sample them
    const Index3& d = storage->geometry.dims;
    storage->labels.resize(std::size_t(storage->geometry.voxel_count()));
#pragma omp parallel for schedule(static)
    for (int64_t k = 0; k < d[2]; ++k)
      for (int64_t j = 0; j < d[1]; ++j)
        for (int64_t i = 0; i < d[0]; ++i)
          storage->labels[std::size_t(storage->geometry.linear_index(i, j, k))] =
              v.labels[std::size_t(v.geometry.linear_index(stride[0] * i, stride[1] * j, stride[2] * k))];
  } else if (with_labels) {
    storage->labels = v.labels;
  }
  return *storage;
}

std::vector<int16_t> voxel_gradients(const RenderVolume& v, bool with_hu) {
  const auto& d = v.geometry.dims;
  std::vector<int16_t> out(std::size_t(v.geometry.voxel_count()) * 4);
#pragma omp parallel for schedule(static)
  for (int64_t k = 0; k < d[2]; ++k)
    for (int64_t j = 0; j < d[1]; ++j)
      for (int64_t i = 0; i < d[0]; ++i) {
        const int64_t n = i + d[0] * (j + d[1] * k);
        const auto g = voxel_gradient(v, i, j, k);
        int16_t* o = &out[std::size_t(4 * n)];
        if (with_hu) {
          o[0] = int16_t(v.hu[n]);
          o[1] = g[0], o[2] = g[1], o[3] = g[2];
        } else {
          o[0] = g[0], o[1] = g[1], o[2] = g[2], o[3] = 0;
        }
      }
  return out;
}

Mat3 RenderVolume::world_to_index() const {
  return (geometry.direction * geometry.spacing_mm.asDiagonal()).inverse();
}

bool RenderVolume::contains(const Vec3& world_mm) const {
  const Vec3 idx = world_to_index() * (world_mm - geometry.origin_mm);
  for (int a = 0; a < 3; ++a)
    if (!(idx[a] >= 0.0 && idx[a] <= static_cast<double>(geometry.dims[a] - 1))) return false;
  return true;
}

const std::vector<int>& organ_label_ids(ColouredOrgan organ) {
  static const std::vector<int> liver{5}, kidneys{2, 3}, arteries{52, 65, 66} /* aorta, iliac arteries */,
      veins{63, 64, 67, 68} /* inferior vena cava, portal vein, iliac veins */, spleen{1}, gallbladder{4}, stomach{6},
      pancreas{7}, small_bowel{18, 19} /* and duodenum */, colon{20};
  switch (organ) {
    case ColouredOrgan::Liver: return liver;
    case ColouredOrgan::Kidneys: return kidneys;
    case ColouredOrgan::Arteries: return arteries;
    case ColouredOrgan::Veins: return veins;
    case ColouredOrgan::Spleen: return spleen;
    case ColouredOrgan::Gallbladder: return gallbladder;
    case ColouredOrgan::Stomach: return stomach;
    case ColouredOrgan::Pancreas: return pancreas;
    case ColouredOrgan::SmallBowel: return small_bowel;
    case ColouredOrgan::Colon: return colon;
  }
  throw std::logic_error("organ_label_ids: unknown organ");
}

void set_organ_colour(LabelColours& c, ColouredOrgan organ, uint8_t r, uint8_t g, uint8_t b) {
  for (int id : organ_label_ids(organ)) c.rgba[std::size_t(id)] = {r, g, b, 255};
}

LabelColours default_label_colours() {
  LabelColours c;
  // Kitasaka 2004 Fig. 6: liver dark red, kidneys yellow, aorta green; the rest chosen to stay
  // apart from those and from the flesh tones of the transfer function.
  using O = ColouredOrgan;
  set_organ_colour(c, O::Liver, 110, 10, 10);
  set_organ_colour(c, O::Kidneys, 235, 205, 30);
  set_organ_colour(c, O::Arteries, 30, 170, 60);
  set_organ_colour(c, O::Veins, 40, 80, 200);
  set_organ_colour(c, O::Spleen, 150, 60, 160);
  set_organ_colour(c, O::Gallbladder, 90, 160, 40);
  set_organ_colour(c, O::Stomach, 230, 140, 150);
  set_organ_colour(c, O::Pancreas, 240, 150, 40);
  set_organ_colour(c, O::SmallBowel, 250, 190, 170);
  set_organ_colour(c, O::Colon, 200, 150, 110);
  return c;
}

std::vector<uint8_t> label_colour_volume(const std::vector<uint16_t>& labels, const LabelColours& c) {
  std::vector<uint8_t> out(labels.size() * 4, 0);
  const int64_t n = int64_t(labels.size());
#pragma omp parallel for schedule(static)
  for (int64_t i = 0; i < n; ++i) {
    const auto p = premultiplied_colour(c, labels[std::size_t(i)]);
    std::copy(p.begin(), p.end(), out.begin() + 4 * i);
  }
  return out;
}

BlockRanges block_ranges(const RenderVolume& v) { return block_ranges(v, v.labels); }

BlockRanges block_ranges(const RenderVolume& v, const std::vector<uint16_t>& labels) {
  const auto& d = v.geometry.dims;
  const int B = kOccupancyBlock;
  BlockRanges r;
  for (int a = 0; a < 3; ++a) r.blocks[a] = std::max<int64_t>(1, (d[a] - 1 + B - 1) / B);
  const int64_t nb = r.blocks[0] * r.blocks[1] * r.blocks[2];
  r.min_hu.assign(nb, 0);
  r.max_hu.assign(nb, 0);
  r.all_exterior.assign(nb, 0);
  const bool has_labels = !labels.empty();
#pragma omp parallel for schedule(dynamic)
  for (int64_t b = 0; b < nb; ++b) {
    const int64_t bx = b % r.blocks[0], by = (b / r.blocks[0]) % r.blocks[1], bz = b / (r.blocks[0] * r.blocks[1]);
    float lo = INFINITY, hi = -INFINITY;
    bool exterior = has_labels;
    // Voxel centres [b·B, (b+1)·B] inclusive, clipped to the grid.
    for (int64_t k = bz * B; k <= std::min<int64_t>((bz + 1) * B, d[2] - 1); ++k)
      for (int64_t j = by * B; j <= std::min<int64_t>((by + 1) * B, d[1] - 1); ++j)
        for (int64_t i = bx * B; i <= std::min<int64_t>((bx + 1) * B, d[0] - 1); ++i) {
          const int64_t n = v.geometry.linear_index(i, j, k);
          lo = std::min(lo, v.hu[n]);
          hi = std::max(hi, v.hu[n]);
          if (has_labels && labels[n] != kExteriorAirLabel) exterior = false;
        }
    r.min_hu[b] = lo;
    r.max_hu[b] = hi;
    r.all_exterior[b] = exterior ? 1 : 0;
  }
  return r;
}

OccupancyGrid occupancy(const BlockRanges& r, const TransferFunction& tf, bool hide_exterior) {
  OccupancyGrid g;
  g.blocks = r.blocks;
  g.occupied.resize(r.min_hu.size());
  for (std::size_t b = 0; b < r.min_hu.size(); ++b) {
    const bool empty = tf.max_opacity(r.min_hu[b], r.max_hu[b]) <= 0.0 || (hide_exterior && r.all_exterior[b]);
    g.occupied[b] = empty ? 0 : 1;
  }
  return g;
}

}  // namespace pneumo
