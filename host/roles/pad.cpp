#include "roles/pad.h"

#include <string>

#include "anatomy/anatomical_axes.h"
#include "roles/role_rules.h"

namespace pneumo {

namespace {
int64_t voxels_for(double mm, double spacing_mm) {
  // The small slack keeps 60 mm at 3 mm spacing at exactly 20 voxels despite rounding.
  return mm > 0 ? int64_t(std::ceil(mm / spacing_mm - 1e-9)) : 0;
}
}  // namespace

PadVoxels pad_voxels(const Geometry& g, const PadMm& mm) {
  const AnatomicalAxes ax = anatomical_axes(g);
  PadVoxels p;
  // The end of a voxel axis that faces a patient direction: the high end when the index grows
  // towards it, else the low end.
  const auto add = [&](int world_axis, bool towards_positive, double want_mm) {
    const int v = ax.axis[world_axis];
    const bool high_end = (ax.sign[world_axis] > 0) == towards_positive;
    (high_end ? p.hi : p.lo)[v] += voxels_for(want_mm, g.spacing_mm[v]);
  };
  add(0, true, mm.lateral);    // patient's right
  add(0, false, mm.lateral);   // patient's left
  add(1, true, mm.anterior);
  add(2, true, mm.superior);
  add(2, false, mm.inferior);
  return p;
}

Geometry padded_geometry(const Geometry& g, const PadVoxels& pad) {
  Geometry out = g;
  for (int a = 0; a < 3; ++a) out.dims[a] = g.dims[a] + pad.lo[a] + pad.hi[a];
  out.origin_mm = g.to_world(Vec3(-double(pad.lo[0]), -double(pad.lo[1]), -double(pad.lo[2])));
  return out;
}

Geometry unpadded_geometry(const Geometry& padded, const PadVoxels& pad) {
  Geometry out = padded;
  for (int a = 0; a < 3; ++a) out.dims[a] = padded.dims[a] - pad.lo[a] - pad.hi[a];
  out.origin_mm = padded.to_world(Vec3(double(pad.lo[0]), double(pad.lo[1]), double(pad.lo[2])));
  return out;
}

Volume pad_volume(const Volume& v, const PadVoxels& pad, double fill) {
  Volume out(padded_geometry(v.geometry(), pad), v.type());
  dispatch_voxel_type(v.type(), const_cast<void*>(v.raw()), [&](auto* src) {
    using T = std::remove_pointer_t<decltype(src)>;
    const T typed_fill = static_cast<T>(fill);
    if (!(static_cast<double>(typed_fill) == fill))
      throw std::invalid_argument("pad_volume: fill " + std::to_string(fill) + " does not fit " +
                                  voxel_type_name(v.type()));
    const std::vector<T> padded = pad_array<T>(src, v.geometry().dims, pad, typed_fill);
    std::memcpy(out.raw(), padded.data(), padded.size() * sizeof(T));
  });
  return out;
}

Volume pad_volume(const Volume& v, const PadMm& pad, double fill) {
  return pad_volume(v, pad_voxels(v.geometry(), pad), fill);
}

}  // namespace pneumo
