// The finite elements on OpenCL (kernels/fem_forces.cl, float32) against the double-precision CPU
// reference (host/solve/fem_force_field.cpp), on every OpenCL device found, on random valid meshes
// and states (a fixed seed (seed_support.h), printed on failure): random roles, cube sizes, moduli, Poisson
// ratios up to 0.49, both laws, Demiray's stiffening, fibres, with and without the mean dilatation, pressure
// and gravity, deformations of up to 10 % of a cube with a rotation of up to a radian.
//
// Tolerance, per node and axis: 64·ε₃₂·S_i with ε₃₂ = 2⁻²³ and S_i the sum of the magnitudes node i's
// force is made of: Σ_t V_t (2μ_t + 3κ_t)|∇N_i,t| (1 + |H_t|) over its tetrahedra (|P| ≤ (2μ + 3κ)(1 + |H|)
// in both laws at these strains, and F = I + H enters with an error of ε₃₂ per entry), the
// magnitudes of its pressure-load and gravity terms. For the stiffness product |H| is replaced by the
// direction's |δF_t| and the scale is the same. Why 64: a polar decomposition by Jacobi rotations and
// sums of up to ~30 terms in float each add a few ε₃₂; a wrong index, a missing term or a sign error
// is orders of magnitude larger.
#include <gtest/gtest.h>

#include <random>

#include "cl/cl_runtime.h"
#include "mesh/adjacency.h"
#include "mesh_test_support.h"
#include "opencl_test_support.h"
#include "solve/fem_element.h"
#include "solve/fem_force_field_cl.h"
#include "solve/force_field.h"
#include "seed_support.h"

using namespace pneumo;

namespace {

constexpr double kEps32 = 1.0 / (1 << 23);

struct RandomCase {
  Mesh mesh;
  std::vector<Vec3> x, dir;
  ForceModel model;
};

RandomCase random_case(std::mt19937& rng) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const RandomVoxels vox = random_voxels(rng, 7);
  const Geometry& g = vox.grid;
  const MeshOptions& mo = vox.options;
  const double young[4] = {2e3 + 80e3 * u(rng), 2e3 + 80e3 * u(rng), 20e3 + 80e3 * u(rng), 20e3 + 80e3 * u(rng)};
  RandomCase c;
  c.mesh = build_mesh(vox.view(), mo, [&](Role, int label) { return young[label]; });
  assign_material(c.mesh, MaterialOptions{});
  c.mesh.tet_poisson.resize(c.mesh.tets.size());
  for (auto& nu : c.mesh.tet_poisson) nu = 0.2 + 0.29 * u(rng);
  // A rotation of the whole state about its centre and a strain of up to 10 % of a cube per node.
  const Vec3 axis = Vec3(u(rng) - 0.5, u(rng) - 0.5, u(rng) - 0.5).normalized();
  const Mat3 Q = Eigen::AngleAxisd(u(rng), axis).toRotationMatrix();
  Vec3 centre = Vec3::Zero();
  for (const Vec3& r : c.mesh.rest_m) centre += r / double(c.mesh.node_count());
  const double h = 1e-3 * g.spacing_mm.minCoeff() * mo.cube_voxels.min();
  for (const Vec3& r : c.mesh.rest_m) {
    c.x.push_back(centre + Q * (r - centre) + 0.1 * h * Vec3(u(rng) - 0.5, u(rng) - 0.5, u(rng) - 0.5));
    c.dir.push_back(h * Vec3(u(rng) - 0.5, u(rng) - 0.5, u(rng) - 0.5));
  }
  // Fibres (fem_element.h) in about half the cases, in a random direction in each tetrahedron and in
  // about 2 of 3 tetrahedra, k₁ up to 2μ.
  if (u(rng) < 0.5) {
    c.mesh.tet_fibre.resize(c.mesh.tets.size());
    c.mesh.tet_fibre_k1_pa.resize(c.mesh.tets.size());
    c.mesh.fibre_k2 = u(rng) < 0.5 ? 0.0 : 5.0 * u(rng);
    for (std::size_t t = 0; t < c.mesh.tets.size(); ++t) {
      c.mesh.tet_fibre[t] = Vec3(u(rng) - 0.5, u(rng) - 0.5, u(rng) - 0.5).normalized();
      c.mesh.tet_fibre_k1_pa[t] = u(rng) < 0.67 ? 2.0 * u(rng) * c.mesh.tet_young_pa[t] / (2.0 * (1.0 + c.mesh.tet_poisson[t])) : 0.0;
    }
  }
  c.model.material = u(rng) < 0.5 ? MaterialModel::FemCorotational : MaterialModel::FemNeoHookean;
  c.model.mean_dilatation = u(rng) < 0.7;
  c.model.stiffening = c.model.material == MaterialModel::FemNeoHookean && u(rng) < 0.5 ? 10.0 * u(rng) : 0.0;
  c.model.damping = false;
  c.model.pressure_pa = u(rng) < 0.8 ? 4000.0 * u(rng) : 0.0;
  c.model.gravity_m_s2 = u(rng) < 0.3 ? Vec3(0, -9.81, 0) : Vec3::Zero();
  return c;
}

/// S_i of the tolerance above, for states x (with_loads) or for the direction of a product; for the
/// diagonal blocks (`diagonal`), whose columns are the products with a unit move of node i alone,
/// |δF_t| = |∇N_i,t| and S_i = Σ_t V_t (2μ_t + 3κ_t)|∇N_i,t|² · 2.
std::vector<double> scales(const RandomCase& c, const std::vector<Vec3>& y, bool product, bool diagonal = false) {
  const Mesh& m = c.mesh;
  std::vector<double> s(m.node_count(), 0.0);
  for (std::size_t t = 0; t < m.tets.size(); ++t) {
    const auto& q = m.tets[t];
    const TetRest rest = tet_rest(m.rest_m[q[0]], m.rest_m[q[1]], m.rest_m[q[2]], m.rest_m[q[3]]);
    const Mat3 D = edge_matrix(y[q[0]], y[q[1]], y[q[2]], y[q[3]]) * rest.dm_inverse;
    const double h = product ? D.norm() : (D - Mat3::Identity()).norm() + 1.0;
    const TetMaterial l = TetMaterial::from_young_poisson(m.tet_young_pa[t], m.tet_poisson[t]);
    // The fibres' k₁ (≤ 2μ; fem_element.h) adds at most 4k₁(1 + |H|)² ≤ 8μ(1 + |H|)² at these strains.
    const double k = l.lambda + l.mu + (m.tet_fibre_k1_pa.empty() ? 0.0 : 3.0 * m.tet_fibre_k1_pa[t]);
    const Mat3& Di = rest.dm_inverse;
    const Vec3 grads[4] = {-(Di.row(0) + Di.row(1) + Di.row(2)).transpose(), Di.row(0).transpose(),
                           Di.row(1).transpose(), Di.row(2).transpose()};
    for (int i = 0; i < 4; ++i)
      s[q[i]] += rest.volume_m3 * (2 * l.mu + 3 * k) * grads[i].norm() * (diagonal ? 2.0 * grads[i].norm() : 1.0 + h);
  }
  if (!product) {
    for (std::size_t l = 0; l < m.load_tet.size(); ++l) {
      const auto f = pressure_load_forces(m, int64_t(l), c.x, c.model.pressure_pa);
      for (int i = 0; i < 4; ++i) s[m.tets[m.load_tet[l]][i]] += f[i].norm();
    }
    for (int64_t n = 0; n < m.node_count(); ++n) s[n] += m.mass_kg[n] * c.model.gravity_m_s2.norm();
  }
  return s;
}

void expect_close(const std::vector<Vec3>& dev, const std::vector<Vec3>& ref, const std::vector<double>& scale,
                  const char* what) {
  ASSERT_EQ(dev.size(), ref.size());
  double worst = 0.0;
  for (std::size_t n = 0; n < ref.size(); ++n)
    for (int a = 0; a < 3; ++a) {
      ASSERT_LE(std::abs(dev[n][a] - ref[n][a]), 64 * kEps32 * scale[n] + 1e-30)
          << what << ", node " << n << " axis " << a << ": device " << dev[n][a] << ", reference " << ref[n][a];
      worst = std::max(worst, std::abs(dev[n][a] - ref[n][a]) / (kEps32 * scale[n] + 1e-300));
    }
  ::testing::Test::RecordProperty(std::string("worst_") + what + "_in_eps_scale", std::to_string(worst));
}

class FemClVsRef : public ::testing::TestWithParam<std::string> {};

TEST_P(FemClVsRef, RandomMeshesAndStatesMatchTheReference) {
  auto ctx = ocl::Context::shared(ocl::parse_device_spec(GetParam()));
  const unsigned seed = testing_support::test_seed(20261211u);
  SCOPED_TRACE("seed " + std::to_string(seed) + " on " + ctx->info().name);
  std::mt19937 rng(seed);
  for (int trial = 0; trial < 16; ++trial) {
    SCOPED_TRACE("trial " + std::to_string(trial));
    const RandomCase c = random_case(rng);
    SCOPED_TRACE(std::string(enum_name(c.model.material)) + (c.model.mean_dilatation ? ", mean dilatation" : "") +
                 ", b " + std::to_string(c.model.stiffening) + (c.mesh.tet_fibre.empty() ? "" : ", fibres"));
    auto ref = make_force_field(c.mesh, c.model);
    auto dev = make_fem_force_field_cl(*ctx, c.mesh, c.model.material);
    std::vector<Vec3> fr, fd, kr, kd;
    ref->evaluate(c.model, c.x, {}, fr);
    dev->evaluate(c.model, c.x, {}, fd);
    expect_close(fd, fr, scales(c, c.x, false), "force");
    ref->linearize(c.model, c.x);
    dev->linearize(c.model, c.x);
    ref->stiffness_product(c.dir, kr);
    dev->stiffness_product(c.dir, kd);
    expect_close(kd, kr, scales(c, c.dir, true), "product");
    // The diagonal blocks: their columns are products with unit moves of one node.
    std::vector<Mat3> br, bd;
    ref->stiffness_diagonal(br);
    dev->stiffness_diagonal(bd);
    const std::vector<double> s_unit = scales(c, c.x, true, true);
    for (int a = 0; a < 3; ++a) {
      std::vector<Vec3> cr(br.size()), cd(bd.size());
      for (std::size_t n = 0; n < br.size(); ++n) { cr[n] = br[n].col(a); cd[n] = bd[n].col(a); }
      expect_close(cd, cr, s_unit, "diagonal");
    }
    // The energy: relative to Σ V (2μ + 3κ)(|H|² + ε), the largest it is built from.
    const double er = ref->elastic_energy(c.model, c.x), ed = dev->elastic_energy(c.model, c.x);
    EXPECT_NEAR(ed, er, 1e-4 * std::abs(er) + 1e-12);
  }
}

TEST_P(FemClVsRef, RestAndRigidMotionsGiveNoForce) {
  // At rest and after a rotation by 2 rad the elastic forces vanish to float rounding of the rotated
  // identity: compared against the forces of a 1 % stretch, 1e-4 of them (a wrong rotation leaves
  // forces of the order of the stretch's).
  auto ctx = ocl::Context::shared(ocl::parse_device_spec(GetParam()));
  std::mt19937 rng(11);
  RandomCase c = random_case(rng);
  c.model.pressure_pa = 0.0;
  c.model.gravity_m_s2 = Vec3::Zero();
  const Mat3 Q = Eigen::AngleAxisd(2.0, Vec3(0.3, -1, 0.5).normalized()).toRotationMatrix();
  std::vector<Vec3> rotated, stretched;
  for (const Vec3& r : c.mesh.rest_m) { rotated.push_back(Q * r); stretched.push_back(1.01 * r); }
  for (MaterialModel law : {MaterialModel::FemCorotational, MaterialModel::FemNeoHookean}) {
    c.model.material = law;
    auto dev = make_fem_force_field_cl(*ctx, c.mesh, law);
    std::vector<Vec3> f0, fr, fs;
    dev->evaluate(c.model, c.mesh.rest_m, {}, f0);
    dev->evaluate(c.model, stretched, {}, fs);
    dev->evaluate(c.model, rotated, {}, fr);
    double m0 = 0, mr = 0, ms = 0;
    for (std::size_t n = 0; n < f0.size(); ++n) {
      m0 = std::max(m0, f0[n].norm());
      mr = std::max(mr, fr[n].norm());
      ms = std::max(ms, fs[n].norm());
    }
    EXPECT_EQ(m0, 0.0) << enum_name(law);
    EXPECT_LT(mr, 1e-4 * ms) << enum_name(law);
  }
}

}  // namespace

GTEST_ALLOW_UNINSTANTIATED_PARAMETERIZED_TEST(FemClVsRef);
INSTANTIATE_TEST_SUITE_P(OpenCL, FemClVsRef, ::testing::ValuesIn(testing_support::opencl_device_specs()),
                         [](const auto& info) { return testing_support::spec_name(info.param); });
