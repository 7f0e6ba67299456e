#include "roles/roles.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "core/error.h"
#include "io/volume_io.h"
#include "roles/auto_pad.h"
#include "roles/auto_roles.h"
#include "anatomy/body_mask.h"
#include "roles/label_map.h"

namespace pneumo {

namespace {

/// HU rules, padding and the warp all compare and interpolate HU values: a NaN or infinite voxel would
/// silently take a role by accident and spread through interpolation. Refused, naming the first.
void check_finite_ct(const Volume& ct, const std::string& name) {
  if (ct.type() != VoxelType::Float32 && ct.type() != VoxelType::Float64) return;   // integers are finite
  const int64_t n = ct.voxel_count();
  int64_t bad = 0, first = n;
  dispatch_voxel_type(ct.type(), const_cast<void*>(ct.raw()), [&](auto* p) {
#pragma omp parallel for reduction(+ : bad) reduction(min : first) schedule(static)
    for (int64_t v = 0; v < n; ++v)
      if (!std::isfinite(static_cast<double>(p[v]))) {
        ++bad;
        first = std::min(first, v);
      }
  });
  if (bad == 0) return;
  const Index3& d = ct.geometry().dims;
  std::ostringstream os;
  os << bad << " voxels are NaN or infinite (the first at voxel (" << first % d[0] << ", " << (first / d[0]) % d[1]
     << ", " << first / (int64_t(d[0]) * d[1]) << ")); replace them (e.g. by -1000 HU, air) before simulating";
  throw file_error(name, os.str());
}

/// A CT that shows no body (all air, or a file that is not the CT in HU) has nothing to inflate: its
/// labels alone would make a wall of air, which the gas would lift as if it were tissue. Refused when
/// fewer than one voxel in a thousand reads as tissue or bone (−500 HU and above: fat is about −100,
/// lung above it −850 to −500, air −1000), naming what was found.
void check_ct_shows_a_body(const Volume& ct, const std::string& name) {
  constexpr double kTissueHu = -500.0, kLeastTissueShare = 1e-3;
  const int64_t n = ct.voxel_count();
  int64_t tissue = 0;
  dispatch_voxel_type(ct.type(), const_cast<void*>(ct.raw()), [&](auto* p) {
#pragma omp parallel for reduction(+ : tissue) schedule(static)
    for (int64_t v = 0; v < n; ++v) tissue += static_cast<double>(p[v]) >= kTissueHu;
  });
  if (double(tissue) >= kLeastTissueShare * double(n)) return;
  std::ostringstream os;
  os << "only " << tissue << " of " << n << " voxels read as tissue or bone (" << kTissueHu
     << " HU and above): this CT shows no body (all air?); give the CT in Hounsfield units";
  throw file_error(name, os.str());
}

Volume padded_ct_float(const Volume& ct, const PadVoxels& pad) {
  Volume out(padded_geometry(ct.geometry(), pad), VoxelType::Float32);
  dispatch_voxel_type(ct.type(), const_cast<void*>(ct.raw()), [&](auto* src) {
    pad_into<float>(src, ct.geometry().dims, pad, -1000.0f, out.data<float>());
  });
  return out;
}

std::vector<uint16_t> padded_labels(const Volume* labels, const Geometry& ct_grid, const PadVoxels& pad) {
  if (!labels) return std::vector<uint16_t>(std::size_t(padded_geometry(ct_grid, pad).voxel_count()), 0);
  return dispatch_voxel_type(labels->type(), const_cast<void*>(labels->raw()), [&](auto* src) {
    return pad_array<uint16_t>(src, labels->geometry().dims, pad, uint16_t(0));
  });
}

}  // namespace

std::array<int64_t, 4> RoleVolume::counts() const {
  const int64_t n = int64_t(role.size());
  int64_t c0 = 0, c1 = 0, c2 = 0, c3 = 0;   // Other, Wall, Viscera, Fixed: integers, so exact on any core count
#pragma omp parallel for schedule(static) reduction(+ : c0, c1, c2, c3)
  for (int64_t v = 0; v < n; ++v) {
    const uint8_t r = uint8_t(role[std::size_t(v)]);
    c0 += r == 0;
    c1 += r == 1;
    c2 += r == 2;
    c3 += r == 3;
  }
  return {c0, c1, c2, c3};
}

double RoleVolume::voxel_volume_ml() const {
  return geometry.spacing_mm[0] * geometry.spacing_mm[1] * geometry.spacing_mm[2] / 1000.0;
}

RoleVolume grown_roles(RoleVolume rv, const PadVoxels& grow) {
  if (grow.empty()) return rv;
  const Index3 dims = rv.geometry.dims;
  RoleVolume g;
  g.geometry = padded_geometry(rv.geometry, grow);
  for (int a = 0; a < 3; ++a) {
    g.pad.lo[a] = rv.pad.lo[a] + grow.lo[a];
    g.pad.hi[a] = rv.pad.hi[a] + grow.hi[a];
  }
  g.role = pad_array<Role>(rv.role.data(), dims, grow, Role::Other);
  g.label = pad_array<uint16_t>(rv.label.data(), dims, grow, uint16_t(0));
  g.ct = padded_ct_float(rv.ct, grow);
  return g;
}

void require_labels_if_needed(const RoleRules& rules, bool have_labels, const RoleInputNames& names) {
  if (rules.source == RoleSource::Labels && !have_labels)
    throw InputError(names.scene +
                     ": roles.source is \"labels\" but inputs.labels is not given; give a label map or set "
                     "roles.source to \"auto\"");
}

RoleVolume assign_roles(const RoleRules& rules, const Volume& ct, const Volume* labels, const RoleInputNames& names) {
  require_labels_if_needed(rules, labels != nullptr, names);
  ct.geometry().validate(names.ct);
  check_finite_ct(ct, names.ct);
  check_ct_shows_a_body(ct, names.ct);
  if (labels) {
    check_labels_on_ct_grid(ct.geometry(), labels->geometry(), names.ct, names.labels);
    check_label_values(*labels, names.labels);
  }
  RoleVolume rv;
  // The automatic rules' body, found once on the CT's own grid: it places the padding (auto_pad.h),
  // then, padded with outside, serves the rules. Air around a slice changes neither its largest part
  // nor which background reaches the slice's border, so it is the body the padded grid would give.
  std::vector<uint8_t> body;
  if (rules.source == RoleSource::Auto) {
    const Volume hu = padded_ct_float(ct, PadVoxels{});   // freed before the padded copy
    body = body_mask(hu.data<float>(), ct.geometry(), rules.auto_body_threshold_hu);
  }
  rv.pad = pad_voxels(ct.geometry(), resolved_pad_mm(rules, body.empty() ? nullptr : &body, ct.geometry()));
  rv.geometry = padded_geometry(ct.geometry(), rv.pad);
  rv.ct = padded_ct_float(ct, rv.pad);
  rv.label = padded_labels(labels, ct.geometry(), rv.pad);
  if (!body.empty()) body = pad_array<uint8_t>(body.data(), ct.geometry().dims, rv.pad, uint8_t(0));
  if (labels) note_label_coverage(rules, rv.label, names.labels);

  if (rules.source == RoleSource::Labels) {
    rv.role = roles_from_labels(rv.label, rules.label_roles());
  } else {
    rv.role = auto_roles(rules, rv.geometry, rv.ct.data<float>(), labels ? rv.label.data() : nullptr, &body);
  }
  return rv;
}

}  // namespace pneumo
