// The exterior views' port marks (pipeline/exterior_views.h) and the skin transfer function.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "pipeline/exterior_views.h"
#include "render/transfer_function.h"

using namespace pneumo;

namespace {

// A 200×150 pinhole at the origin looking along +y, and a flat surface 100 mm in front of it.
ViewCamera front_camera() {
  Optics o;
  o.fov_deg = 40.0;
  return make_view_camera(look_at_pose(Vec3(0, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1)), o, 200, 150);
}

RenderImage wall_at(const ViewCamera& c, double depth_mm) {
  RenderImage im;
  im.width = c.width;
  im.height = c.height;
  im.rgba.assign(std::size_t(4) * c.width * c.height, 0.2f);
  im.depth_mm.assign(std::size_t(c.width) * c.height, float(depth_mm));
  return im;
}

// Pixels of the mark's yellow within r px of (x, y).
int yellow_near(const RgbImage& im, double x, double y, int r) {
  int n = 0;
  for (int v = int(y) - r; v <= int(y) + r; ++v)
    for (int u = int(x) - r; u <= int(x) + r; ++u)
      if (u >= 0 && v >= 0 && u < im.width && v < im.height && im.pixel(u, v)[0] == 255 && im.pixel(u, v)[1] == 230 &&
          im.pixel(u, v)[2] == 0)
        ++n;
  return n;
}

}  // namespace

TEST(ExteriorViews, MarksOnlyPortsOnTheVisibleSkin) {
  // Compared: a mark 5 mm behind the surface (a skin point a little inside the skin) is drawn as a
  // ring around the pixel it projects to; one 60 mm behind (the far side of the body, beyond the
  // 20 mm tolerance), one behind the camera and one outside the image are not drawn and not listed.
  const ViewCamera c = front_camera();
  const RenderImage im = wall_at(c, 100.0);
  const Vec3 skin(10, 105, -5), far_side(-10, 160, 5), behind(0, -50, 0), outside(500, 100, 0);
  const AnnotatedView a = annotated_view(im, c, "after", {{"left", skin}, {"far", far_side}, {"back", behind},
                                                          {"out", outside}});
  ASSERT_EQ(a.marked, std::vector<std::string>{"left"});
  const Eigen::Vector2d p = *c.project(skin);
  EXPECT_GT(yellow_near(a.image, p.x(), p.y(), 6), 8);
  EXPECT_EQ(yellow_near(a.image, p.x(), p.y(), 1), 0);   // a ring: the skin point itself stays visible
  const Eigen::Vector2d q = *c.project(far_side);
  EXPECT_EQ(yellow_near(a.image, q.x(), q.y(), 6), 0);
  // Where no surface was found (depth infinite) every mark in the image is drawn.
  RenderImage empty = wall_at(c, std::numeric_limits<double>::infinity());
  EXPECT_EQ(annotated_view(empty, c, "", {{"far", far_side}}).marked, std::vector<std::string>{"far"});
}

TEST(ExteriorViews, SkinStopsRaysAtTheBodysSurface) {
  // Compared: the skin preset is clear in air and in gas (−1000 … −600 HU), opaque from −400 HU (fat at
  // −100, muscle at 50), one colour; the settings drop label colours and light the body from the camera's
  // distance to the grid's centre.
  const TransferFunction tf = preset_transfer_function(RenderPreset::Skin);
  EXPECT_EQ(tf.opacity_at(-1000), 0.0);
  EXPECT_EQ(tf.opacity_at(-650), 0.0);
  EXPECT_EQ(tf.opacity_at(-100), 1.0);
  EXPECT_EQ(tf.opacity_at(50), 1.0);
  EXPECT_GT(tf.opacity_at(-500), 0.0);
  EXPECT_LT(tf.opacity_at(-500), 1.0);
  EXPECT_EQ(tf.colour_at(-100), tf.colour_at(300));
  Geometry g;
  g.dims = {21, 21, 11};
  g.spacing_mm = Vec3(2, 2, 3);
  g.origin_mm = Vec3(-20, -20, -15);
  const std::vector<ExteriorCamera> cams = exterior_cameras(g, 64, 48);
  ASSERT_EQ(cams.size(), 2u);
  EXPECT_EQ(cams[0].name, "exterior_anterior");
  EXPECT_GT(cams[0].camera.position_mm.y(), 20.0);   // in front of the body (RAS: +y anterior)
  EXPECT_LT(cams[1].camera.position_mm.x(), -20.0);  // at the patient's left (−x)
  RenderSettings s;
  s.show_labels = true;
  const RenderSettings e = skin_settings(s, cams[0].camera, g);
  EXPECT_FALSE(e.show_labels);
  EXPECT_NEAR(e.light_falloff_mm, cams[0].camera.position_mm.norm(), 1e-9);   // the grid is centred at 0
}
