#pragma once
// Exterior views: the body's skin as a surface (the "skin" transfer function, the iso-surface near
// -500 HU), from in front and from the left, before and after inflation side by side, each port
// marked where its skin point lies. The same cameras frame both panels, so the rise of the dome is
// read by comparing them.
#include <optional>
#include <string>
#include <vector>

#include "image/image.h"
#include "render/camera_model.h"
#include "render/render_settings.h"

namespace pneumo {

struct ExteriorCamera {
  std::string name;   // "exterior_anterior", "exterior_left"
  ViewCamera camera;
};

/// The anterior and left cameras around grid `g`: a 40° pinhole at the distance where the grid's
/// bounding sphere fills the width, image up along +z (superior).
std::vector<ExteriorCamera> exterior_cameras(const Geometry& g, int width, int height);
/// The one of them named "exterior_<side>" (side "anterior" or "left"); nullopt for another side.
std::optional<ExteriorCamera> exterior_camera(const Geometry& g, const std::string& side, int width, int height);

/// `s` with the skin transfer function and no label colours; the headlight's falloff distance set
/// to the camera's distance from the grid's centre, so the body is lit as the cavity is from inside.
RenderSettings skin_settings(const RenderSettings& s, const ViewCamera& camera, const Geometry& g);

struct SkinMark {
  std::string name;
  Vec3 point_mm = Vec3::Zero();
};

/// How far behind the surface a ray found a mark may lie and still be drawn (mm): a skin point
/// given a few mm inside the skin is marked; one on the far side of the body (tens of cm) is not.
inline constexpr double kMarkDepthToleranceMm = 20.0;

/// Where `point_mm` shows on a rendered view: its pixel when it projects into the image and lies no
/// deeper than kMarkDepthToleranceMm behind the first surface along that pixel's ray; nullopt else.
std::optional<Eigen::Vector2d> visible_on_view(const RenderImage& image, const ViewCamera& camera, const Vec3& point_mm);
/// The same on a view's depth (camera.width × camera.height, mm to the first surface per pixel).
std::optional<Eigen::Vector2d> visible_on_view(const std::vector<float>& depth_mm, const ViewCamera& camera,
                                               const Vec3& point_mm);

/// Pixels whose centres lie between r_in and r_out of (cx, cy), set to `c` (r_in < 0: a disc).
void draw_ring(RgbImage& image, double cx, double cy, double r_in, double r_out, Rgb c);

struct AnnotatedView {
  RgbImage image;
  std::vector<std::string> marked;   // the marks drawn (visible from this camera)
};

/// Draws on `image` (a render's 8-bit copy, or one drawn over) each mark of `marks` visible on the
/// render `im` (visible_on_view) as a ring with its name, and `caption` at the top-left; returns the
/// names drawn.
std::vector<std::string> draw_marks(RgbImage& image, const RenderImage& im, const ViewCamera& camera,
                                    const std::string& caption, const std::vector<SkinMark>& marks);

/// A rendered view as an 8-bit image: `caption` at the top-left, each visible mark as a ring with
/// its name. A mark is visible when it projects into the image and lies no deeper than
/// kMarkDepthToleranceMm behind the first surface along its pixel's ray.
AnnotatedView annotated_view(const RenderImage& image, const ViewCamera& camera, const std::string& caption,
                             const std::vector<SkinMark>& marks);

}  // namespace pneumo
