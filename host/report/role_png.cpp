#include "report/role_png.h"

#include <cstdio>

#include "image/png.h"
#include "report/slices.h"

namespace pneumo {

namespace {

std::vector<OverlayClass> role_classes(const RoleVolume& rv) {
  // Indexed by Role's value. Alpha 0.45: the anatomy stays readable under the colour.
  const std::array<double, 4> ml = rv.volumes_ml();
  const auto entry = [&](Role r, Rgb colour, double alpha) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%s %.2f L", role_name(r), ml[std::size_t(r)] / 1000.0);
    return OverlayClass{buf, colour, alpha};
  };
  std::vector<OverlayClass> t(4);
  t[size_t(Role::Other)] = {"other (not coloured)", {0, 0, 0}, 0.0};
  t[size_t(Role::Wall)] = entry(Role::Wall, {255, 140, 0}, 0.45);
  t[size_t(Role::Viscera)] = entry(Role::Viscera, {40, 210, 80}, 0.45);
  t[size_t(Role::Fixed)] = entry(Role::Fixed, {60, 110, 255}, 0.5);
  return t;
}

}  // namespace

RgbImage render_roles(const RoleVolume& rv, const std::optional<Vec3>& point_mm) {
  SliceOverlay overlay;
  overlay.geometry = rv.geometry;
  // Role is an enum over uint8_t: its bytes are the class values.
  overlay.classes = reinterpret_cast<const uint8_t*>(rv.role.data());
  overlay.table = role_classes(rv);
  SliceView view;
  view.point_mm = point_mm;
  const Index3& d = rv.geometry.dims;
  char title[160];
  std::snprintf(title, sizeof title, "roles on %lldx%lldx%lld voxels (%s), CT window %g..%g HU",
                (long long)d[0], (long long)d[1], (long long)d[2], rv.geometry.orientation_code().c_str(),
                view.window.low_hu, view.window.high_hu);
  view.title = title;
  return stack_rows({render_slice_row(rv.ct, &overlay, view), render_legend(overlay.table)});
}

void write_roles_png(const RoleVolume& rv, const std::string& png_path, const std::optional<Vec3>& point_mm) {
  write_png(png_path, render_roles(rv, point_mm));
}

}  // namespace pneumo
