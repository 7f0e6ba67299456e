// The captions the report gives each view and fly-through (pipeline/report_views.h).
#include <gtest/gtest.h>

#include "pipeline/report_views.h"

using namespace pneumo;

TEST(ReportViews, CaptionsSayWhatEachViewShows) {
  // Compared: a port's caption names its skin point, its target by the label's name, the depth, the
  // scope angle, roll, lens and field of view; a camera's its position and aim; an exterior view what is
  // before and after and which ports it marks; a fly-through its frames, keyframes and frame rate.
  ViewSettings r;
  Port p;
  p.name = "umbilical";
  p.skin_point_mm = Vec3(0, 120, -10);
  p.target_label = 5;
  p.insertion_mm = 40;
  p.optics.oblique_deg = 30;
  p.optics.roll_deg = 15;
  r.ports.push_back(p);
  Camera c;
  c.name = "overview";
  c.position_mm = Vec3(0, 50, 0);
  c.look_at_mm = Vec3(0, 0, 0);
  c.optics.lens = Lens::Fisheye;
  c.optics.fov_deg = 120;
  r.cameras.push_back(c);
  CameraPath path;
  path.name = "liver";
  path.frames = 12;
  path.keyframes = {{Vec3(0, 0, 0), Vec3(0, 1, 0)}, {Vec3(0, 10, 0), Vec3(0, 11, 0)}, {Vec3(0, 20, 0), Vec3(0, 21, 0)}};
  r.paths.push_back(path);
  r.video_fps = 12;
  const std::map<int, std::string> names{{5, "liver"}};
  const std::string port = view_caption("umbilical", r, names);
  for (const char* part : {"(0, 120, -10) mm", "liver (label 5)", "40 mm", "30° oblique", "rolled 15°", "70° pinhole"})
    EXPECT_NE(port.find(part), std::string::npos) << part << " in: " << port;
  EXPECT_NE(view_caption("umbilical", r, {}).find("label 5"), std::string::npos);
  const std::string cam = view_caption("overview", r, names);
  for (const char* part : {"(0, 50, 0) mm", "looking at (0, 0, 0) mm", "120° fisheye"})
    EXPECT_NE(cam.find(part), std::string::npos) << part << " in: " << cam;
  EXPECT_EQ(view_caption("nothing", r, names), "");

  const nlohmann::json render = {
      {"views",
       {{{"name", "umbilical"}, {"file", "views/umbilical.png"}},
        {{"name", "exterior_anterior"}, {"file", "views/exterior_anterior.png"}, {"preset", "skin"},
         {"panels", {"before", "after"}},
         {"ports_marked", {{"before", {"umbilical"}}, {"after", {"umbilical"}}}}}}},
      {"paths", {{{"name", "liver"}, {"frames", 12}, {"strip", {{"file", "flythrough/liver_strip.jpg"},
                                                                {"frame_px", {160, 120}}}}}}}};
  ReportContent rc;
  add_rendered_views(rc, render, r, names, "/run");
  ASSERT_EQ(rc.views.size(), 2u);
  EXPECT_EQ(rc.views[0].path, "/run/views/umbilical.png");
  EXPECT_EQ(rc.views[0].caption, port);
  EXPECT_EQ(rc.views[1].title, "Exterior, anterior");
  for (const char* part : {"before inflation (left)", "after it (right)", "Ports marked in yellow: umbilical."})
    EXPECT_NE(rc.views[1].caption.find(part), std::string::npos) << part << " in: " << rc.views[1].caption;
  ASSERT_EQ(rc.flythroughs.size(), 1u);
  const ReportAnimation& a = rc.flythroughs[0];
  EXPECT_EQ(a.strip_path, "/run/flythrough/liver_strip.jpg");
  EXPECT_EQ(a.frames, 12);
  EXPECT_EQ(a.frame_width, 160);
  EXPECT_EQ(a.frame_height, 120);
  EXPECT_EQ(a.fps, 12.0);
  EXPECT_TRUE(a.video_link.empty());
  for (const char* part : {"12 frames through 3 keyframes", "at 12 frames/s"})
    EXPECT_NE(a.caption.find(part), std::string::npos) << part << " in: " << a.caption;
}
