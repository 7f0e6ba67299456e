#include "pipeline/exterior_views.h"

#include <cmath>

#include "image/text.h"
#include "render/image_out.h"
#include "render/transfer_function.h"

namespace pneumo {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kExteriorFovDeg = 40.0;
const Rgb kMarkColour{255, 230, 0};     // yellow: stands out from the skin tone and the black background
const Rgb kCaptionColour{255, 255, 255};

struct Frame {
  Vec3 centre;
  double radius;
};

Frame grid_frame(const Geometry& g) {
  const Vec3 last(double(g.dims[0] - 1), double(g.dims[1] - 1), double(g.dims[2] - 1));
  return {g.to_world(0.5 * last), 0.5 * (g.to_world(Vec3::Zero()) - g.to_world(last)).norm()};
}

double camera_distance(double radius) { return radius / std::sin(kExteriorFovDeg * kPi / 360.0); }

}  // namespace

void draw_ring(RgbImage& im, double cx, double cy, double r_in, double r_out, Rgb c) {
  for (int y = int(std::floor(cy - r_out)); y <= int(std::ceil(cy + r_out)); ++y)
    for (int x = int(std::floor(cx - r_out)); x <= int(std::ceil(cx + r_out)); ++x) {
      const double d = std::hypot(x + 0.5 - cx, y + 0.5 - cy);
      if (d >= r_in && d <= r_out) im.set(x, y, c);
    }
}

std::optional<Eigen::Vector2d> visible_on_view(const std::vector<float>& depth_mm, const ViewCamera& camera,
                                               const Vec3& point_mm) {
  const std::optional<Eigen::Vector2d> p = camera.project(point_mm);
  if (!p || p->x() < 0 || p->y() < 0 || p->x() >= camera.width || p->y() >= camera.height) return std::nullopt;
  const double surface = depth_mm[std::size_t(int(p->y())) * std::size_t(camera.width) + std::size_t(int(p->x()))];
  const double along = (point_mm - camera.position_mm).norm();
  if (std::isfinite(surface) && along > surface + kMarkDepthToleranceMm) return std::nullopt;   // behind the body
  return p;
}

std::optional<Eigen::Vector2d> visible_on_view(const RenderImage& im, const ViewCamera& camera, const Vec3& point_mm) {
  return visible_on_view(im.depth_mm, camera, point_mm);
}

std::vector<ExteriorCamera> exterior_cameras(const Geometry& g, int width, int height) {
  const Frame f = grid_frame(g);
  const double dist = camera_distance(f.radius);
  Optics o;
  o.fov_deg = kExteriorFovDeg;
  o.near_mm = dist - f.radius;
  std::vector<ExteriorCamera> cams;
  // RAS: the patient's right is +x, anterior +y; the left view looks at the left flank from outside.
  const std::pair<const char*, Vec3> sides[] = {{"exterior_anterior", Vec3(0, 1, 0)}, {"exterior_left", Vec3(-1, 0, 0)}};
  for (const auto& [name, side] : sides)
    cams.push_back({name, make_view_camera(look_at_pose(f.centre + dist * side, f.centre, Vec3(0, 0, 1)), o, width,
                                           height)});
  return cams;
}

std::optional<ExteriorCamera> exterior_camera(const Geometry& g, const std::string& side, int width, int height) {
  for (ExteriorCamera& c : exterior_cameras(g, width, height))
    if (c.name == "exterior_" + side) return c;
  return std::nullopt;
}

RenderSettings skin_settings(const RenderSettings& s, const ViewCamera& camera, const Geometry& g) {
  RenderSettings e = s;
  e.tf = preset_transfer_function(RenderPreset::Skin);
  e.show_labels = false;
  e.hide_exterior_air = false;
  e.vignetting_power = 0.0;   // a camera outside the body, not through the scope
  e.light_falloff_mm = (camera.position_mm - grid_frame(g).centre).norm();
  return e;
}

std::vector<std::string> draw_marks(RgbImage& out, const RenderImage& im, const ViewCamera& camera,
                                    const std::string& caption, const std::vector<SkinMark>& marks) {
  std::vector<std::string> marked;
  const int scale = im.width >= 400 ? 2 : 1;
  const double r = 4.0 * scale;
  for (const SkinMark& m : marks) {
    const std::optional<Eigen::Vector2d> p = visible_on_view(im, camera, m.point_mm);
    if (!p) continue;
    draw_ring(out, p->x(), p->y(), r - scale, r + scale, Rgb{0, 0, 0});                // a dark rim: readable on any tone
    draw_ring(out, p->x(), p->y(), r - 0.5 * scale, r + 0.5 * scale, kMarkColour);
    draw_text(out, int(p->x() + r + 2 * scale), int(p->y()) - text_height_px(scale) / 2, m.name, kMarkColour, scale);
    marked.push_back(m.name);
  }
  draw_text(out, 4 * scale, 4 * scale, caption, kCaptionColour, scale);
  return marked;
}

AnnotatedView annotated_view(const RenderImage& im, const ViewCamera& camera, const std::string& caption,
                             const std::vector<SkinMark>& marks) {
  AnnotatedView out;
  out.image = RgbImage(im.width, im.height);
  out.image.rgb = to_rgb8(im);
  out.marked = draw_marks(out.image, im, camera, caption, marks);
  return out;
}

}  // namespace pneumo
