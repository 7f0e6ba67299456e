#pragma once
// Whether an output grid holds an input grid: the warp's output is the input CT's grid grown by
// whole voxels where the deformed body left it (host/warp/warp_mesh.h growth_to_hold_deformed), so
// it keeps the spacing and direction and holds the input's voxels at whole indices.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "core/geometry.h"

namespace pneumo::testing_support {

inline void expect_holds_grid(const Geometry& outer, const Geometry& inner, const std::string& what) {
  EXPECT_LT((outer.spacing_mm - inner.spacing_mm).norm(), 1e-6) << what;
  EXPECT_LT((outer.direction - inner.direction).norm(), 1e-6) << what;
  const Vec3 at = outer.to_index(inner.origin_mm);
  for (int a = 0; a < 3; ++a) {
    EXPECT_NEAR(at[a], std::round(at[a]), 1e-4) << what << ", axis " << a;
    EXPECT_GE(std::round(at[a]), 0.0) << what << ", axis " << a;
    EXPECT_LE(std::round(at[a]) + double(inner.dims[a]), double(outer.dims[a])) << what << ", axis " << a;
  }
}

}  // namespace pneumo::testing_support
