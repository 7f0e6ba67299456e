#pragma once
// Analytic phantoms and helpers for the renderer's tests.
//
// The cavity phantom: soft tissue (40 HU) filling the grid, a spherical gas cavity (−1000 HU) at
// the centre, and an organ (a sphere at 60 HU, label 5 = liver) whose centre sits on the cavity
// wall so that half of it bulges into the gas. Edges are a linear partial-volume ramp one voxel
// wide, and HU are rounded to integers so the 16-bit texture path holds them exactly.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "render/gl_context.h"
#include "render/render_volume.h"

namespace pneumo::testing_support {

struct CavityPhantom {
  double spacing_mm = 1.5;
  int n = 64;                       // voxels per axis
  double k_spacing_mm = 0;          // > 0: anisotropic, this spacing along the third axis (same extent)
  double cavity_radius_mm = 35.0;   // centred on the world origin
  Vec3 organ_centre_mm = Vec3(0.0, -35.0, 0.0);
  double organ_radius_mm = 14.0;
  int organ_label = 5;
};

inline double ramp(double signed_distance_mm, double width_mm) {
  return std::clamp(0.5 - signed_distance_mm / width_mm, 0.0, 1.0);  // 1 inside, 0 outside
}

/// Volume on an n³ grid centred on the origin, direction identity unless `direction` is given.
inline RenderVolume make_cavity_phantom(const CavityPhantom& p = {}, const Mat3& direction = Mat3::Identity()) {
  RenderVolume v;
  const double sk = p.k_spacing_mm > 0 ? p.k_spacing_mm : p.spacing_mm;
  const int nk = int(std::lround(p.n * p.spacing_mm / sk));
  v.geometry.dims = {p.n, p.n, nk};
  v.geometry.spacing_mm = Vec3(p.spacing_mm, p.spacing_mm, sk);
  v.geometry.direction = direction;
  v.geometry.origin_mm = -direction * Vec3(0.5 * (p.n - 1) * p.spacing_mm, 0.5 * (p.n - 1) * p.spacing_mm,
                                           0.5 * (nk - 1) * sk);
  v.hu.resize(v.geometry.voxel_count());
  v.labels.resize(v.geometry.voxel_count());
  for (int k = 0; k < nk; ++k)
    for (int j = 0; j < p.n; ++j)
      for (int i = 0; i < p.n; ++i) {
        const Vec3 w = v.geometry.to_world(Vec3(i, j, k));
        const double in_cavity = ramp(w.norm() - p.cavity_radius_mm, p.spacing_mm);
        const double in_organ = ramp((w - p.organ_centre_mm).norm() - p.organ_radius_mm, p.spacing_mm);
        double hu = 40.0 * (1 - in_cavity) - 1000.0 * in_cavity;
        hu = hu * (1 - in_organ) + 60.0 * in_organ;
        const int64_t n = v.geometry.linear_index(i, j, k);
        v.hu[n] = float(std::nearbyint(hu));
        v.labels[n] = (w - p.organ_centre_mm).norm() <= p.organ_radius_mm ? uint16_t(p.organ_label) : 0;
      }
  v.hu_is_int16 = true;
  return v;
}

/// The process's GL context, or nullptr with the reason in `why` when none can be created at all.
inline GlContext* try_gl_context(std::string& why) {
  try {
    return &shared_gl_context();
  } catch (const std::exception& e) {
    why = e.what();
    return nullptr;
  }
}

#define PNEUMO_REQUIRE_GL(ctx_var)                                                         \
  std::string gl_why_;                                                                     \
  GlContext* ctx_var = ::pneumo::testing_support::try_gl_context(gl_why_);                 \
  if (!ctx_var) GTEST_SKIP() << "no OpenGL context can be created here: " << gl_why_

}  // namespace pneumo::testing_support
