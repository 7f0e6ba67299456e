// TetField (host/validate/tet_field.h), which reads a mesh's node field at arbitrary rest points for
// Lamé's check on the true spheres. Compared against a linear field u = A X + c given at the nodes,
// which linear tetrahedra reproduce exactly inside and, by linear extrapolation, outside: inside
// random tetrahedra of a random mesh, and half a cube beyond its lowest face, to 1e-12 of |u|
// (rounding only; a wrong tetrahedron or weight is off by the field's change over a cube). And the
// Fibonacci points: on the unit sphere, their mean at the centre and their mean z² a third, as a
// uniform spread's (tolerance 1/n, the lattice's quadrature error for these smooth moments).
#include <gtest/gtest.h>

#include <random>

#include "mesh_test_support.h"
#include "validate/tet_field.h"

namespace pneumo {
namespace {

TEST(TetField, LinearFieldsAreReadExactlyInsideAndBeyondTheMesh) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int trial = 0; trial < 6; ++trial) {
    SCOPED_TRACE("trial " + std::to_string(trial));
    RandomVoxels vox = random_voxels(rng, 7);
    vox.grid.spacing_mm = Vec3::Constant(vox.grid.spacing_mm[0]);   // cubes: isotropic spacing
    const Mesh m = build_mesh(vox.view(), vox.options, [](Role, int) { return 10e3; });
    ASSERT_GT(m.tets.size(), 0u);
    const double cube_m = 1e-3 * vox.grid.spacing_mm[0] * vox.options.cube_voxels[0];
    Mat3 A;
    A << 0.1, -0.2, 0.3, 0.05, 0.4, -0.1, -0.3, 0.2, 0.15;
    const Vec3 c(1e-3, -2e-3, 5e-4);
    std::vector<Vec3> field(m.node_count());
    for (int64_t n = 0; n < m.node_count(); ++n) field[n] = A * m.rest_m[n] + c;
    const TetField tf(m, cube_m);
    for (int k = 0; k < 50; ++k) {
      const auto& q = m.tets[rng() % m.tets.size()];
      double w[4], sum = 0;
      for (double& x : w) sum += (x = u(rng) + 1e-3);
      Vec3 p = Vec3::Zero();
      for (int i = 0; i < 4; ++i) p += w[i] / sum * m.rest_m[q[i]];
      bool outside = true;
      const Vec3 got = tf.at(p, field, outside);
      EXPECT_FALSE(outside);
      EXPECT_LE((got - (A * p + c)).norm(), 1e-12 * (A * p + c).norm());
    }
    // Half a cube below the mesh's lowest node along x: in no meshed cube.
    int64_t low = 0;
    for (int64_t n = 1; n < m.node_count(); ++n)
      if (m.rest_m[n].x() < m.rest_m[low].x()) low = n;
    const Vec3 p = m.rest_m[low] - Vec3(0.5 * cube_m, 0, 0);
    bool outside = false;
    const Vec3 got = tf.at(p, field, outside);
    EXPECT_TRUE(outside);
    EXPECT_LE((got - (A * p + c)).norm(), 1e-12 * (A * p + c).norm());
    // Far from every cube.
    EXPECT_THROW(tf.at(m.rest_m[low] - Vec3(5 * cube_m, 0, 0), field, outside), std::logic_error);
  }
}

TEST(TetField, FibonacciPointsSpreadEvenlyOverTheSphere) {
  const int n = 8192;
  const std::vector<Vec3> d = fibonacci_sphere(n);
  Vec3 mean = Vec3::Zero();
  double z2 = 0.0;
  for (const Vec3& v : d) {
    EXPECT_NEAR(v.norm(), 1.0, 1e-12);
    mean += v / n;
    z2 += v.z() * v.z() / n;
  }
  EXPECT_LE(mean.norm(), 1.0 / n);
  EXPECT_NEAR(z2, 1.0 / 3.0, 1.0 / n);
}

}  // namespace
}  // namespace pneumo
