#include "roles/auto_pad.h"

#include <algorithm>
#include <limits>

#include "core/log.h"
#include "anatomy/anatomical_axes.h"

namespace pneumo {

BodyClearance body_clearance(const std::vector<uint8_t>& body, const Geometry& g) {
  const SliceFrame f = slice_frame(g);
  const AnatomicalAxes ax = anatomical_axes(g);
  int64_t most_anterior = -1, lat_lo = f.n_lat, lat_hi = -1;
  for (int64_t s = 0; s < f.n_si; ++s)
    for (int64_t a = 0; a < f.n_ap; ++a)
      for (int64_t l = 0; l < f.n_lat; ++l)
        if (body[std::size_t(f.index(l, a, s))]) {
          most_anterior = std::max(most_anterior, f.ant(a));
          lat_lo = std::min(lat_lo, l);
          lat_hi = std::max(lat_hi, l);
        }
  BodyClearance c;
  if (most_anterior < 0) return c;   // no body: assign_roles refuses such a CT before this matters
  c.anterior_mm = double(f.n_ap - 1 - most_anterior) * f.h_ap;
  const double low_end = double(lat_lo) * f.h_lat, high_end = double(f.n_lat - 1 - lat_hi) * f.h_lat;
  // The lateral voxel axis grows towards the patient's right (x, RAS) when its sign is +.
  const bool high_is_right = ax.sign[0] > 0;
  c.right_mm = high_is_right ? high_end : low_end;
  c.left_mm = high_is_right ? low_end : high_end;
  return c;
}

PadMm resolved_pad_mm(const RoleRules& r, const std::vector<uint8_t>* body, const Geometry& g) {
  PadMm p{r.pad_anterior_mm.value_or(0.0), r.pad_lateral_mm.value_or(0.0), r.pad_superior_mm, r.pad_inferior_mm};
  // roles.source "labels" describes every voxel itself, its air included (the phantoms): nothing is added.
  if ((r.pad_anterior_mm && r.pad_lateral_mm) || r.source != RoleSource::Auto) return p;
  if (!body) return p;
  const BodyClearance c = body_clearance(*body, g);
  if (!r.pad_anterior_mm && c.anterior_mm < kAutoPadMm) p.anterior = kAutoPadMm;
  if (!r.pad_lateral_mm && std::min(c.right_mm, c.left_mm) < kAutoPadMm) p.lateral = kAutoPadMm;
  if (p.anterior > 0 || p.lateral > 0)
    log::info("roles: the body comes within " + std::to_string(int(std::min({c.anterior_mm, c.right_mm, c.left_mm}) + 0.5)) +
              " mm of the CT's edge (anterior " + std::to_string(int(c.anterior_mm + 0.5)) + ", right " +
              std::to_string(int(c.right_mm + 0.5)) + ", left " + std::to_string(int(c.left_mm + 0.5)) +
              " mm): air added, " + std::to_string(int(p.anterior)) + " mm in front and " +
              std::to_string(int(p.lateral)) + " mm at each side, so the wall has room to rise");
  return p;
}

}  // namespace pneumo
