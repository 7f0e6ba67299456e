// The mesh's own gas volume (enclosed_cavity_volume, mesh.h; deformation_metrics' cavity_volume_ml)
// where the CT's first and last slices cut the cavity off, as on a real CT whose field of view ends
// inside the abdomen. A wall slab over a viscera block spanning every slice; the wall's nodes lifted
// by a sine bump that vanishes at the slab's lateral ends: the gas is closed laterally and open only
// at the two axial cut planes. Its volume is known in closed form: the slices' thickness times the
// area under the lift, which the tetrahedra interpolate linearly between nodes (the trapezoid rule
// over the node spacing is then exact). Tolerance 1e-9 relative: rounding only.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "core/units.h"
#include "mesh/mesh.h"
#include "pipeline/simulate.h"

using namespace pneumo;

namespace {

constexpr int64_t kNLat = 24, kNAp = 12, kNSi = 4;
constexpr double kPeakLiftMm = 5.3;

double lift_mm(double lat_index) { return kPeakLiftMm * std::sin(M_PI * (lat_index - 1.5) / 20.0); }

/// A grid whose voxel axes `lat`, `ap`, `si` run along world x, y, z (each reversed where `flip`).
struct Layout {
  int lat = 0, ap = 1, si = 2;
  Vec3 flip{1, 1, 1};
  Geometry grid() const {
    Geometry g;
    Index3 d{1, 1, 1};
    d[lat] = kNLat, d[ap] = kNAp, d[si] = kNSi;
    g.dims = d;
    g.spacing_mm = Vec3(1.0, 1.0, 1.0);
    g.direction = Mat3::Zero();
    g.direction(0, lat) = flip[0], g.direction(1, ap) = flip[1], g.direction(2, si) = flip[2];
    return g;
  }
};

Mesh slab_mesh(const Layout& lay) {
  const Geometry g = lay.grid();
  std::vector<Role> roles(std::size_t(g.voxel_count()), Role::Other);
  std::vector<uint16_t> labels(roles.size(), 0);
  for (int64_t s = 0; s < kNSi; ++s)
    for (int64_t a = 2; a < 9; ++a)
      for (int64_t l = 2; l < kNLat - 2; ++l) {
        int64_t ijk[3];
        ijk[lay.lat] = l, ijk[lay.ap] = a, ijk[lay.si] = s;
        const std::size_t v = std::size_t(g.linear_index(ijk[0], ijk[1], ijk[2]));
        roles[v] = a >= 6 ? Role::Wall : Role::Viscera;
        labels[v] = a >= 6 ? 1 : 2;
      }
  MeshOptions opt;
  opt.cube_voxels = 1;
  return build_mesh(VoxelRoles{g, roles.data(), labels.data()}, opt, [](Role, int) { return 1000.0; });
}

/// Wall nodes lifted along the ap voxel axis by lift_mm(their lateral index); the viscera's stay.
std::vector<Vec3> lifted(const Mesh& m, const Layout& lay) {
  std::vector<Vec3> x = m.rest_m;
  const Vec3 ap_axis = m.grid.direction.col(lay.ap);
  for (int64_t n = 0; n < m.node_count(); ++n) {
    if (m.node_part[std::size_t(n)] != Part::Wall) continue;
    const double l = m.grid.to_index(units::m_to_mm(1.0) * m.rest_m[std::size_t(n)])[lay.lat];
    x[std::size_t(n)] += units::mm_to_m(lift_mm(l)) * ap_axis;
  }
  return x;
}

/// kNSi slices of 1 mm times the area under the lift, trapezoids between nodes at ½-offsets (ml).
double exact_gas_ml() {
  double area_mm2 = 0.0;
  for (int64_t c = 2; c < kNLat - 2; ++c) area_mm2 += 0.5 * (lift_mm(c - 0.5) + lift_mm(c + 0.5));
  return double(kNSi) * area_mm2 / 1000.0;
}

}  // namespace

TEST(CavityVolume, ACavityCutOffByTheFirstAndLastSlicesIsMeasuredExactly) {
  const Layout ras;
  const Mesh m = slab_mesh(ras);
  ASSERT_GT(m.stats.cavity_faces, 0);
  const std::vector<Vec3> x = lifted(m, ras);
  const Vec3 origin = Vec3(0.012, 0.006, 0.002);
  const Vec3 axial(0, 0, 1);
  const double in_plane_ml = (enclosed_cavity_volume(m, x, origin, axial) - enclosed_cavity_volume(m, m.rest_m, origin, axial)) * 1e6;
  EXPECT_NEAR(in_plane_ml, exact_gas_ml(), 1e-9 * exact_gas_ml());
  // The ⅓(x − origin) field misses the caps' flux: about a third here, with the origin mid-slab.
  const double radial_ml = (enclosed_cavity_volume(m, x, origin) - enclosed_cavity_volume(m, m.rest_m, origin)) * 1e6;
  EXPECT_LT(radial_ml, 0.8 * exact_gas_ml());
}

// deformation_metrics finds the axial planes from the grid, however it is stored: slices along i,
// j or k, axes flipped.
TEST(CavityVolume, DeformationMetricsFindTheAxialCutInAnyGridLayout) {
  for (const Layout& lay : {Layout{0, 1, 2, Vec3(1, 1, 1)}, Layout{1, 2, 0, Vec3(-1, 1, -1)},
                            Layout{2, 0, 1, Vec3(1, -1, 1)}}) {
    SCOPED_TRACE("lat " + std::to_string(lay.lat) + " ap " + std::to_string(lay.ap) + " si " + std::to_string(lay.si));
    const Mesh m = slab_mesh(lay);
    EXPECT_NEAR(deformation_metrics(m, lifted(m, lay)).cavity_volume_ml, exact_gas_ml(), 1e-9 * exact_gas_ml());
  }
}

// The viscera's tissue volume change (deformation_metrics' viscera_volume_change_ml): zero under a
// translation, (s³ − 1) × their volume under a uniform scaling by s; the slab's viscera fill 4 slices
// × 4 × 20 voxels of 1 mm³ whole, so their volume is 0.32 ml. Rounding only: 1e-9 relative.
TEST(CavityVolume, VisceraVolumeChangeIsZeroWhenMovedAndExactWhenScaled) {
  const Layout ras;
  const Mesh m = slab_mesh(ras);
  const double viscera_ml = double(kNSi) * 4.0 * double(kNLat - 4) / 1000.0;   // mm³ → ml
  ASSERT_NEAR(viscera_ml, 0.32, 1e-12);
  std::vector<Vec3> moved = m.rest_m, scaled = m.rest_m;
  const double s = 1.1;
  for (std::size_t n = 0; n < moved.size(); ++n) {
    moved[n] += Vec3(0.003, -0.002, 0.010);
    scaled[n] *= s;
  }
  EXPECT_NEAR(deformation_metrics(m, moved).viscera_volume_change_ml, 0.0, 1e-9 * viscera_ml);
  EXPECT_NEAR(deformation_metrics(m, scaled).viscera_volume_change_ml, (s * s * s - 1.0) * viscera_ml,
              1e-9 * viscera_ml);
}
