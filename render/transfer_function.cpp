#include "render/transfer_function.h"

#include <algorithm>
#include <cmath>

#include "core/error.h"
#include "render/tissue_colour.h"
#include "render/view_settings.h"

namespace pneumo {
namespace {

// Piecewise-linear interpolation of column `c` of points (HU in column 0).
template <std::size_t N>
double interpolate(const std::vector<std::array<double, N>>& pts, double hu, std::size_t c) {
  if (pts.empty()) return 0.0;
  if (hu <= pts.front()[0]) return pts.front()[c];
  if (hu >= pts.back()[0]) return pts.back()[c];
  for (std::size_t i = 1; i < pts.size(); ++i) {
    if (hu <= pts[i][0]) {
      const double h0 = pts[i - 1][0], h1 = pts[i][0];
      if (h1 <= h0) return pts[i][c];  // a step
      const double w = (hu - h0) / (h1 - h0);
      return pts[i - 1][c] + w * (pts[i][c] - pts[i - 1][c]);
    }
  }
  return pts.back()[c];
}

}  // namespace

double TransferFunction::opacity_at(double hu) const { return interpolate(opacity, hu, 1); }

Vec3 TransferFunction::colour_at(double hu) const {
  return Vec3(interpolate(colour, hu, 1), interpolate(colour, hu, 2), interpolate(colour, hu, 3));
}

double TransferFunction::max_opacity(double lo, double hi) const {
  // The maximum of a piecewise-linear function on [lo, hi] is at an end or at a point inside.
  double m = std::max(opacity_at(lo), opacity_at(hi));
  for (const auto& p : opacity)
    if (p[0] > lo && p[0] < hi) m = std::max(m, p[1]);
  return m;
}

std::vector<float> TransferFunction::table_rgba(double hu_min, int n) const {
  std::vector<float> t(static_cast<std::size_t>(n) * 4);
  for (int i = 0; i < n; ++i) {
    const double hu = hu_min + i;
    const Vec3 c = colour_at(hu);
    t[4 * i + 0] = static_cast<float>(c.x());
    t[4 * i + 1] = static_cast<float>(c.y());
    t[4 * i + 2] = static_cast<float>(c.z());
    t[4 * i + 3] = static_cast<float>(opacity_at(hu));
  }
  return t;
}

void TransferFunction::validate(const std::string& what) const {
  if (opacity.empty() || colour.empty())
    throw InputError(what + ": a transfer function needs at least one opacity point and one colour point");
  for (std::size_t i = 0; i < opacity.size(); ++i) {
    if (i > 0 && opacity[i][0] < opacity[i - 1][0])
      throw InputError(what + ": opacity points must have non-decreasing HU");
    if (!(opacity[i][1] >= 0.0 && opacity[i][1] <= 1.0))
      throw InputError(what + ": opacity " + std::to_string(opacity[i][1]) + " is outside 0 to 1");
  }
  for (std::size_t i = 0; i < colour.size(); ++i) {
    if (i > 0 && colour[i][0] < colour[i - 1][0])
      throw InputError(what + ": colour points must have non-decreasing HU");
    for (int c = 1; c < 4; ++c)
      if (!(colour[i][c] >= 0.0 && colour[i][c] <= 1.0))
        throw InputError(what + ": colour component " + std::to_string(colour[i][c]) + " is outside 0 to 1");
  }
}

TransferFunction preset_transfer_function(RenderPreset preset) {
  TransferFunction tf;
  tf.name = enum_name(preset);
  switch (preset) {
    case RenderPreset::Laparoscopic: {
      // Gas and air clear; tissue reaches near-full opacity within 1-2 mm so surfaces look solid
      // as they do through a laparoscope. Colours are computed from the tissues' published optical
      // make-up (render/tissue_colour.h): adipose tissue at fat's -100 HU, skeletal muscle at 40 HU,
      // liver at 65 HU (unenhanced parenchyma), blended linearly between; bone off-white. Below
      // -100 HU the colour darkens towards the -300 HU point, the partial-volume rim between gas
      // and fat (clear below -160 HU, so it shows only as the edge of a surface).
      tf.opacity = {{-1024, 0}, {-300, 0}, {-160, 0}, {-110, 0.35}, {-60, 0.6}, {0, 0.8}, {40, 0.9}, {300, 1}};
      auto point = [](double hu, Tissue t) {
        const Vec3 c = tissue_srgb(tissue_optics(t));
        return std::array<double, 4>{hu, c.x(), c.y(), c.z()};
      };
      tf.colour = {{-1024, 0.0, 0.0, 0.0}, {-300, 0.35, 0.28, 0.22}, point(-100, Tissue::Adipose),
                   point(40, Tissue::Muscle), point(65, Tissue::Liver), {250, 0.95, 0.88, 0.78},
                   {1000, 1.0, 0.98, 0.94}};
      break;
    }
    case RenderPreset::CtSoftTissue:  // Slicer "CT-Soft-Tissue"
      tf.opacity = {{-2048, 0}, {-167.01, 0}, {-160, 1}, {240, 1}, {3071, 1}};
      tf.colour = {{-2048, 0, 0, 0}, {-167.01, 0, 0, 0}, {-160, 0.0556, 0.0556, 0.0556}, {240, 1, 1, 1}, {3071, 1, 1, 1}};
      break;
    case RenderPreset::CtMuscle:  // Slicer "CT-Muscle"
      tf.opacity = {{-3024, 0}, {-155.407, 0}, {217.641, 0.676}, {419.736, 0.833}, {3071, 0.804}};
      tf.colour = {{-3024, 0, 0, 0},
                   {-155.407, 0.549, 0.251, 0.149},
                   {217.641, 0.882, 0.604, 0.290},
                   {419.736, 1, 0.937, 0.955},
                   {3071, 0.827, 0.659, 1}};
      break;
    case RenderPreset::CtAaa:  // Slicer "CT-AAA"
      tf.opacity = {{-3024, 0}, {143.556, 0}, {166.222, 0.686}, {214.389, 0.696}, {419.736, 0.833}, {3071, 0.804}};
      tf.colour = {{-3024, 0, 0, 0},
                   {143.556, 0.616, 0.357, 0.184},
                   {166.222, 0.882, 0.604, 0.290},
                   {214.389, 1, 1, 1},
                   {419.736, 1, 0.937, 0.955},
                   {3071, 0.827, 0.659, 1}};
      break;
    case RenderPreset::CtAir:  // Slicer "CT-Air": air opaque, everything above -500 HU clear
      tf.opacity = {{-3024, 0.706}, {-900.046, 0.716}, {-500, 0}, {3071, 0}};
      tf.colour = {{-3024, 1, 1, 1}, {-900.046, 0.2, 1, 1}, {-500, 0.3, 1, 0.3}, {3071, 1, 1, 1}};
      break;
    case RenderPreset::Skin:
      // The body's outer surface, the iso-surface near -500 HU between air (-1000) and fat or skin
      // (-100 and above) that surface renderings of the skin use: clear below -600 HU, opaque within
      // the first 1 mm above -400 HU, so a ray from outside stops at the skin and gas inside the body
      // never shows. One colour, 3D Slicer's "skin" entry of its GenericAnatomyColors table
      // (177, 122, 101), so that the shape reads from the shading alone.
      tf.opacity = {{-3024, 0}, {-600, 0}, {-400, 1}, {3071, 1}};
      tf.colour = {{-3024, 0.694, 0.478, 0.396}, {3071, 0.694, 0.478, 0.396}};
      break;
    case RenderPreset::Custom:
      throw InputError("the \"custom\" preset takes its points from render.custom_opacity and custom_colour");
  }
  return tf;
}

LabelColours preset_label_colours(RenderPreset preset) {
  LabelColours c = default_label_colours();
  if (preset != RenderPreset::Laparoscopic) return c;
  // Organs whose optical make-up is published take their computed colour (render/tissue_colour.h);
  // the rest keep the identifying colours of default_label_colours().
  auto set = [&](ColouredOrgan organ, Tissue t) {
    const Vec3 rgb = tissue_srgb(tissue_optics(t));
    auto byte = [](double v) { return uint8_t(std::lround(255.0 * v)); };
    set_organ_colour(c, organ, byte(rgb.x()), byte(rgb.y()), byte(rgb.z()));
  };
  set(ColouredOrgan::Liver, Tissue::Liver);
  set(ColouredOrgan::Kidneys, Tissue::Kidney);
  set(ColouredOrgan::Pancreas, Tissue::Pancreas);
  set(ColouredOrgan::SmallBowel, Tissue::Bowel);
  set(ColouredOrgan::Colon, Tissue::Bowel);
  return c;
}

TransferFunction scene_transfer_function(const ViewSettings& render) {
  if (render.preset != RenderPreset::Custom) return preset_transfer_function(render.preset);
  TransferFunction tf;
  tf.name = "custom";
  const auto& o = render.custom_opacity;
  const auto& c = render.custom_colour;
  if (o.size() % 2 != 0 || c.size() % 4 != 0)
    throw InputError("render.custom_opacity takes pairs [HU, opacity, ...] and custom_colour quadruples "
                     "[HU, r, g, b, ...]");
  for (std::size_t i = 0; i + 1 < o.size(); i += 2) tf.opacity.push_back({o[i], o[i + 1]});
  for (std::size_t i = 0; i + 3 < c.size(); i += 4) tf.colour.push_back({c[i], c[i + 1], c[i + 2], c[i + 3]});
  tf.validate("render.preset \"custom\"");
  return tf;
}

}  // namespace pneumo
