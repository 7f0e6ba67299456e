// The OpenCL force evaluation (kernels/msd_forces.cl, float32) against the double-precision CPU
// reference (host/solve/forces.cpp), on every OpenCL device found, on random valid meshes and states
// (a fixed seed (seed_support.h), printed on failure): random roles, cube sizes, moduli, deformations,
// velocities, pressure, volume stiffness, gravity, both spring models.
//
// Tolerance, per node and axis: 32·ε₃₂·S_i, where ε₃₂ = 2⁻²³ and S_i is the sum of the magnitudes
// the node's force is built from (Σ k_ij·(|d₀,ij| + 2|u|max) over its springs, Σ c_ij·|v|max over its
// dampers, the magnitudes of its triangle, tetrahedron and gravity terms). Why: the device works on
// displacements u and rounded rest vectors d₀, so a spring's inputs carry a relative error ε₃₂ of
// its length and of the displacements (which k multiplies), and it then sums up to ~40 terms in
// float; a few ε₃₂ per term, with headroom, is 32·ε₃₂. A wrong index, a missing term or a sign error
// is orders of magnitude larger, and so is the ~50× larger rounding of absolute world positions.
#include <gtest/gtest.h>

#include <random>

#include "cl/cl_runtime.h"
#include "mesh_test_support.h"
#include "opencl_test_support.h"
#include "mesh/adjacency.h"
#include "solve/forces.h"
#include "solve/forces_cl.h"
#include "seed_support.h"

using namespace pneumo;

namespace {

struct RandomCase {
  Mesh mesh;
  std::vector<Vec3> x, v;
  ForceModel model;
};

RandomCase random_case(std::mt19937& rng) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const RandomVoxels vox = random_voxels(rng, 8);
  const Geometry& g = vox.grid;
  const MeshOptions& mo = vox.options;
  const double young[4] = {20e3 + 80e3 * u(rng), 20e3 + 80e3 * u(rng), 20e3 + 80e3 * u(rng), 20e3 + 80e3 * u(rng)};
  RandomCase c;
  c.mesh = build_mesh(vox.view(), mo, [&](Role, int label) { return young[label]; });
  MaterialOptions mat;
  mat.damping_ratio = 2.0 * u(rng);
  assign_material(c.mesh, mat);
  const double h = 1e-3 * g.spacing_mm.minCoeff();
  for (const Vec3& r : c.mesh.rest_m) {
    c.x.push_back(r + 0.1 * h * Vec3(u(rng) - 0.5, u(rng) - 0.5, u(rng) - 0.5));
    c.v.push_back(0.05 * Vec3(u(rng) - 0.5, u(rng) - 0.5, u(rng) - 0.5));
  }
  c.model.spring_model = u(rng) < 0.5 ? SpringModel::Nonlinear : SpringModel::Linear;
  c.model.damping = u(rng) < 0.8;
  c.model.pressure_pa = u(rng) < 0.8 ? 4000.0 * u(rng) : 0.0;
  c.model.volume_stiffness_pa = u(rng) < 0.5 ? 60e3 * u(rng) : 0.0;
  c.model.gravity_m_s2 = u(rng) < 0.3 ? Vec3(0, -9.81, 0) : Vec3::Zero();
  c.model.stiffening = u(rng) < 0.5 ? 20.0 * u(rng) : 0.0;
  return c;
}

/// Σ of the magnitudes node n's force is made of (see the tolerance above).
std::vector<double> force_scales(const RandomCase& c) {
  const Mesh& m = c.mesh;
  double umax = 0, vmax = 0;
  for (int64_t n = 0; n < m.node_count(); ++n) umax = std::max(umax, (c.x[n] - m.rest_m[n]).norm());
  for (const auto& p : c.v) vmax = std::max(vmax, p.cwiseAbs().maxCoeff());
  std::vector<double> s(m.node_count(), 0.0);
  for (std::size_t e = 0; e < m.springs.size(); ++e)
    for (int32_t n : m.springs[e])
      s[n] += m.spring_k[e] * (m.spring_rest_m[e] + 2 * umax +
                               m.spring_rest_m[e] * stiffened_strain(2 * umax / m.spring_rest_m[e], c.model.stiffening)) +
              (c.model.damping ? m.spring_c[e] * vmax : 0.0);
  for (std::size_t l = 0; l < m.load_tet.size(); ++l) {
    const auto f = pressure_load_forces(m, int64_t(l), c.x, c.model.pressure_pa);
    for (int i = 0; i < 4; ++i) s[m.tets[m.load_tet[l]][i]] += f[i].norm();
  }
  for (std::size_t t = 0; t < m.tets.size(); ++t) {
    const auto& q = m.tets[t];
    const auto g = tet_volume_gradient(c.x[q[0]], c.x[q[1]], c.x[q[2]], c.x[q[3]]);
    const double vol = signed_tet_volume(c.x[q[0]], c.x[q[1]], c.x[q[2]], c.x[q[3]]);
    const double v0 = m.tet_rest_volume_m3[t];
    for (int i = 0; i < 4; ++i)
      s[q[i]] += std::abs(c.model.volume_stiffness_pa) * m.tet_fraction[t] * (std::abs(vol - v0) / v0 + 1.0) * g[i].norm();
  }
  for (int64_t n = 0; n < m.node_count(); ++n) s[n] += m.mass_kg[n] * c.model.gravity_m_s2.norm();
  return s;
}

class ForcesClVsRef : public ::testing::TestWithParam<std::string> {};

TEST_P(ForcesClVsRef, RandomMeshesAndStatesMatchTheReference) {
  auto ctx = ocl::Context::shared(ocl::parse_device_spec(GetParam()));
  const unsigned seed = testing_support::test_seed(20261207u);
  SCOPED_TRACE("seed " + std::to_string(seed) + " on " + ctx->info().name);
  std::mt19937 rng(seed);
  constexpr double kEps32 = 1.0 / (1 << 23);
  for (int trial = 0; trial < 20; ++trial) {
    SCOPED_TRACE("trial " + std::to_string(trial));
    const RandomCase c = random_case(rng);
    std::vector<Vec3> ref, dev;
    ForceEvaluator(c.mesh).evaluate(c.model, c.x, c.v, ref);
    ClForceEvaluator cl(*ctx, c.mesh);
    cl.upload_state(c.x, c.v);
    cl.evaluate(c.model);
    cl.download_forces(dev);
    const std::vector<double> scale = force_scales(c);
    for (int64_t n = 0; n < c.mesh.node_count(); ++n)
      for (int a = 0; a < 3; ++a)
        ASSERT_LE(std::abs(dev[n][a] - ref[n][a]), 32 * kEps32 * scale[n] + 1e-30)
            << "node " << n << " axis " << a << ": device " << dev[n][a] << ", reference " << ref[n][a];
  }
}

TEST_P(ForcesClVsRef, StateStaysOnTheDeviceBetweenEvaluations) {
  // Evaluating twice without uploading again gives the same bits: nothing is lost or re-uploaded. And
  // both are the reference's forces (the tolerance above), not zeros: two evaluations that both lost
  // the state would agree too.
  auto ctx = ocl::Context::shared(ocl::parse_device_spec(GetParam()));
  std::mt19937 rng(7);
  RandomCase c = random_case(rng);
  c.model.pressure_pa = 2000.0;   // a load on every case: the forces cannot all be zero
  ClForceEvaluator cl(*ctx, c.mesh);
  cl.upload_state(c.x, c.v);
  std::vector<Vec3> first, second, ref;
  cl.evaluate(c.model);
  cl.download_forces(first);
  cl.evaluate(c.model);
  cl.download_forces(second);
  EXPECT_EQ(first, second);
  ForceEvaluator(c.mesh).evaluate(c.model, c.x, c.v, ref);
  const std::vector<double> scale = force_scales(c);
  constexpr double kEps32 = 1.0 / (1 << 23);
  double largest = 0.0;
  for (int64_t n = 0; n < c.mesh.node_count(); ++n) {
    largest = std::max(largest, second[n].norm());
    for (int a = 0; a < 3; ++a)
      ASSERT_LE(std::abs(second[n][a] - ref[n][a]), 32 * kEps32 * scale[n] + 1e-30) << "node " << n << " axis " << a;
  }
  EXPECT_GT(largest, 0.0) << "the device returned no force at all";
}

TEST_P(ForcesClVsRef, FreeNodesOnlySkipsExactlyTheFullyHeldNodes) {
  // Compared: an evaluation of the free nodes only (what the solvers run) against a full one, bit for bit
  // on every node with a free axis (the same blocks, the same order of sums), and zero on every node held
  // on all three axes (skipped, never written). Random meshes with fixed voxels; a fixed seed (seed_support.h).
  auto ctx = ocl::Context::shared(ocl::parse_device_spec(GetParam()));
  const unsigned seed = testing_support::test_seed(20261208u);
  SCOPED_TRACE("seed " + std::to_string(seed));
  std::mt19937 rng(seed);
  int64_t held_seen = 0, free_seen = 0;
  for (int trial = 0; trial < 10; ++trial) {
    const RandomCase c = random_case(rng);
    std::vector<Vec3> all, free;
    ClForceEvaluator skip(*ctx, c.mesh);
    skip.upload_state(c.x, c.v);
    skip.evaluate(c.model, ClForceEvaluator::Nodes::Free);
    skip.download_forces(free);
    ClForceEvaluator full(*ctx, c.mesh);
    full.upload_state(c.x, c.v);
    full.evaluate(c.model);
    full.download_forces(all);
    for (int64_t n = 0; n < c.mesh.node_count(); ++n) {
      if (c.mesh.hold[n] == kHoldAll) {
        ++held_seen;
        EXPECT_EQ(free[n], Vec3::Zero()) << "held node " << n;
      } else {
        ++free_seen;
        EXPECT_EQ(free[n], all[n]) << "free node " << n;
      }
    }
    EXPECT_LE(skip.gathered_fraction(ClForceEvaluator::Nodes::Free), 1.0);
  }
  EXPECT_GT(held_seen, 0);   // the random meshes did hold nodes, so the skip was exercised
  EXPECT_GT(free_seen, 0);
}

}  // namespace

GTEST_ALLOW_UNINSTANTIATED_PARAMETERIZED_TEST(ForcesClVsRef);
INSTANTIATE_TEST_SUITE_P(OpenCL, ForcesClVsRef, ::testing::ValuesIn(testing_support::opencl_device_specs()), [](const auto& info) { return testing_support::spec_name(info.param); });
