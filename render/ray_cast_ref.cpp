#include "render/ray_cast_ref.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

namespace pneumo {
namespace {

struct Sampler {
  const RenderVolume& v;
  int64_t nx, ny, nz;

  explicit Sampler(const RenderVolume& vol)
      : v(vol), nx(vol.geometry.dims[0]), ny(vol.geometry.dims[1]), nz(vol.geometry.dims[2]) {}

  float at(int64_t i, int64_t j, int64_t k) const { return v.hu[i + nx * (j + ny * k)]; }

  // Trilinear blend of per-voxel values `at(i, j, k)` at a continuous index; positions beyond the voxel centres
  // clamp to the edge.
  template <class T, class At>
  T trilinear(const Vec3& p, const At& at) const {
    const double x = std::clamp(p.x(), 0.0, double(nx - 1));
    const double y = std::clamp(p.y(), 0.0, double(ny - 1));
    const double z = std::clamp(p.z(), 0.0, double(nz - 1));
    const int64_t i = std::min<int64_t>(int64_t(x), nx - 1), j = std::min<int64_t>(int64_t(y), ny - 1),
                  k = std::min<int64_t>(int64_t(z), nz - 1);
    const int64_t i1 = std::min(i + 1, nx - 1), j1 = std::min(j + 1, ny - 1), k1 = std::min(k + 1, nz - 1);
    const double fx = x - i, fy = y - j, fz = z - k;
    const T c00 = at(i, j, k) * (1 - fx) + at(i1, j, k) * fx;
    const T c10 = at(i, j1, k) * (1 - fx) + at(i1, j1, k) * fx;
    const T c01 = at(i, j, k1) * (1 - fx) + at(i1, j, k1) * fx;
    const T c11 = at(i, j1, k1) * (1 - fx) + at(i1, j1, k1) * fx;
    return (c00 * (1 - fy) + c10 * fy) * (1 - fz) + (c01 * (1 - fy) + c11 * fy) * fz;
  }

  // Trilinear HU.
  double hu(const Vec3& p) const {
    return trilinear<double>(p, [&](int64_t i, int64_t j, int64_t k) { return double(at(i, j, k)); });
  }

  // Trilinear interpolation of the per-voxel gradients (voxel_gradient(), HU per voxel index).
  Vec3 gradient(const Vec3& p) const {
    return kGradientHalf * trilinear<Vec3>(p, [&](int64_t i, int64_t j, int64_t k) {
             const auto q = voxel_gradient(v, i, j, k);
             return Vec3(q[0], q[1], q[2]);
           });
  }

  // Trilinear premultiplied label colour (premultiplied_colour(), 0..1 per channel).
  Eigen::Vector4d label_colour(const Vec3& p, const LabelColours& colours) const {
    if (v.labels.empty()) return Eigen::Vector4d::Zero();
    return trilinear<Eigen::Vector4d>(p, [&](int64_t i, int64_t j, int64_t k) {
             const auto q = premultiplied_colour(colours, v.labels[i + nx * (j + ny * k)]);
             return Eigen::Vector4d(q[0], q[1], q[2], q[3]);
           }) / 255.0;
  }

  uint16_t label(const Vec3& p) const {
    if (v.labels.empty()) return 0;
    const int64_t i = std::clamp<int64_t>(int64_t(std::floor(p.x() + 0.5)), 0, nx - 1);
    const int64_t j = std::clamp<int64_t>(int64_t(std::floor(p.y() + 0.5)), 0, ny - 1);
    const int64_t k = std::clamp<int64_t>(int64_t(std::floor(p.z() + 0.5)), 0, nz - 1);
    return v.labels[i + nx * (j + ny * k)];
  }
};

// [t0, t1] where origin + t·dir (index space) lies within [0, d−1] on every axis; empty if t0 > t1.
std::pair<double, double> clip_to_box(const Vec3& o, const Vec3& d, const Index3& dims) {
  double t0 = -std::numeric_limits<double>::infinity(), t1 = std::numeric_limits<double>::infinity();
  for (int a = 0; a < 3; ++a) {
    const double hi = double(dims[a] - 1);
    if (std::abs(d[a]) < 1e-12) {
      if (o[a] < 0.0 || o[a] > hi) return {1.0, 0.0};
      continue;
    }
    double ta = (0.0 - o[a]) / d[a], tb = (hi - o[a]) / d[a];
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
  }
  return {t0, t1};
}

}  // namespace

RenderImage render_reference(const RenderVolume& input, const ViewCamera& cam, const RenderSettings& s) {
  std::optional<RenderVolume> smoothed;   // the views' reconstruction, built per call (the reference is slow anyway)
  const RenderVolume& volume = volume_as_viewed(input, smoothed);
  RenderImage img;
  img.width = cam.width;
  img.height = cam.height;
  img.rgba.assign(std::size_t(cam.width) * cam.height * 4, 0.0f);
  img.depth_mm.assign(std::size_t(cam.width) * cam.height, std::numeric_limits<float>::infinity());
  const Sampler smp(volume);
  const Mat3 w2i = volume.world_to_index();
  const Mat3 w2i_t = w2i.transpose();
  const Vec3 origin_idx = w2i * (cam.position_mm - volume.geometry.origin_mm);
  const double exponent = s.step_mm / kOpacityUnitMm;

#pragma omp parallel for schedule(dynamic, 1)
  for (int py = 0; py < cam.height; ++py) {
    for (int px = 0; px < cam.width; ++px) {
      const auto dir = cam.ray(px + 0.5 + s.pixel_offset_x, py + 0.5 + s.pixel_offset_y);
      if (!dir) continue;
      const Vec3 didx = w2i * *dir;  // index units per mm along the ray
      const auto [ta, tb] = clip_to_box(origin_idx, didx, volume.geometry.dims);
      const double t_lo = std::max(ta, cam.near_mm);
      if (!(t_lo <= tb)) continue;
      double j = s.jitter ? jitter_offset(px, py, s.jitter_seed) : 0.0;
      int64_t k = std::max<int64_t>(0, int64_t(std::ceil((t_lo - cam.near_mm) / s.step_mm - j)));
      Vec3 C = Vec3::Zero();
      double A = 0.0;
      double depth = std::numeric_limits<double>::infinity();
      const auto clear_at = [&](const Vec3& q) {
        return (s.hide_exterior_air && smp.label(q) == kExteriorAirLabel) || s.tf.opacity_at(smp.hu(q)) <= 0.0;
      };
      double t_clear = -1.0;   // the last t known to contribute nothing, while no sample since has; else −1
      for (;; ++k) {
        double t = cam.near_mm + (double(k) + j) * s.step_mm;
        if (t > tb) break;
        if (t < t_lo) continue;
        Vec3 p = origin_idx + t * didx;
        if (clear_at(p)) {
          t_clear = t;
          continue;
        }
        if (t_clear >= 0.0) {
          // Step 2b: entering matter from clear space, bisect for where the opacity begins and go on from there.
          double lo = t_clear, hi = t;
          for (int r = 0; r < kEntryBisections; ++r) {
            const double mid = 0.5 * (lo + hi);
            (clear_at(origin_idx + mid * didx) ? lo : hi) = mid;
          }
          t = hi + 0.5 * s.step_mm;   // the first sample half a step in: a midpoint sum from the entry on
          j = (t - cam.near_mm) / s.step_mm - double(k);
          if (t > tb) break;
          p = origin_idx + t * didx;
          if (clear_at(p)) {   // a layer thinner than half a step
            t_clear = t;
            continue;
          }
        }
        t_clear = -1.0;
        const double h = smp.hu(p);
        const double alpha = s.tf.opacity_at(h);
        const double a = 1.0 - std::pow(1.0 - std::min(alpha, 1.0), exponent);
        Vec3 c = s.tf.colour_at(h);
        if (s.show_labels) {
          const Eigen::Vector4d lc = smp.label_colour(p, s.label_colours);
          c = (1.0 - s.label_opacity * lc[3]) * c + s.label_opacity * lc.head<3>();
        }
        const Vec3 g = w2i_t * smp.gradient(p);
        double diffuse = 1.0, specular = 0.0;
        if (g.norm() >= kFlatGradient) {
          const double ndl = std::abs(g.normalized().dot(*dir));
          diffuse = ndl;
          specular = std::pow(ndl, s.shininess);
        }
        const double att = 1.0 / (1.0 + (t / s.light_falloff_mm) * (t / s.light_falloff_mm));
        const Vec3 shaded = c * (s.ambient + s.diffuse * diffuse * att) + Vec3::Constant(s.specular * specular * att);
        C += (1.0 - A) * a * shaded;
        A += (1.0 - A) * a;
        if (A >= kDepthOpacity && !std::isfinite(depth)) depth = t;
        if (A > kEarlyTermination) break;
      }
      const std::size_t n = std::size_t(py) * cam.width + px;
      if (s.vignetting_power > 0.0) C *= std::pow(std::max(0.0, cam.forward.dot(*dir)), s.vignetting_power);
      for (int c = 0; c < 3; ++c) img.rgba[4 * n + c] = float(std::clamp(C[c], 0.0, 1.0));
      img.rgba[4 * n + 3] = float(A);
      img.depth_mm[n] = float(depth);
    }
  }
  return img;
}

}  // namespace pneumo
