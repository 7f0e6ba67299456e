// The finite elements (solve/fem_element.h, the FEM force field) against truths computed here:
// rotations carry no stress, the stress is the energy's gradient and the stiffness product the
// forces' Jacobian (central finite differences), small strains obey Hooke's law, and a uniform
// strain is reproduced exactly (the patch test). The same derivative checks hold for the springs'
// stiffness, which the Newton solver uses too.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "core/error.h"
#include "core/progress.h"
#include "mesh/mesh.h"
#include "solve/fem_element.h"
#include "solve/force_field.h"
#include "solve/pressure_stiffness.h"
#include "solve/solve_on_device.h"
#include "solve/solver.h"
#include "validate/validate.h"
#include "fem_test_support.h"
#include "mesh_test_support.h"
#include "opencl_test_support.h"

namespace pneumo {
namespace {

const uint32_t kSeed = 20261202u;
const TetMaterial kLame = TetMaterial::from_young_poisson(60e3, 0.45);

Mat3 rotation(const Vec3& axis, double angle) { return Eigen::AngleAxisd(angle, axis.normalized()).toRotationMatrix(); }

using testing_support::random_matrix;

struct LawCase {
  FemLaw law;
  double b;
  const char* name;
};
const LawCase kLaws[] = {{FemLaw::Corotational, 0.0, "corotational"},
                         {FemLaw::NeoHookean, 0.0, "neo-Hookean"},
                         {FemLaw::NeoHookean, 4.0, "Demiray b=4"}, {FemLaw::NeoHookean, 10.0, "Demiray b=10"}};

TEST(FemElement, PolarDecompositionIsARotationTimesASymmetricStretch) {
  // Compared: R S against F, RᵀR against I, det R against +1 and S against Sᵀ, for random F and for
  // an inverted F (det < 0), which must keep a proper rotation. Tolerance 1e-12: rounding of a 3×3 SVD.
  std::mt19937 rng(kSeed);
  for (int k = 0; k < 20; ++k) {
    Mat3 F = Mat3::Identity() + random_matrix(rng, 0.5);
    if (k % 4 == 0) F.col(0) *= -1.0;   // inverted
    const Polar p = polar_decomposition(F);
    EXPECT_LT((p.R * p.S - F).norm(), 1e-12);
    EXPECT_LT((p.R.transpose() * p.R - Mat3::Identity()).norm(), 1e-12);
    EXPECT_NEAR(p.R.determinant(), 1.0, 1e-12);
    EXPECT_LT((p.S - p.S.transpose()).norm(), 1e-12);
  }
}

TEST(FemElement, RotationsOfAnySizeCarryNoStressOrEnergy) {
  // Compared: ψ and P of a pure rotation (up to 3 rad, near a half turn) against zero, for every law.
  // Tolerance 1e-9 of μ: rounding (a rotation is exactly stress-free in both laws).
  for (const LawCase& c : kLaws)
    for (double angle : {0.1, 1.0, 2.0, 3.0}) {
      SCOPED_TRACE(std::string(c.name) + " angle " + std::to_string(angle));
      const ElementState s = element_state(c.law, rotation(Vec3(1, 2, -0.5), angle), c.b);
      EXPECT_LT(std::abs(energy_density(s, kLame)), 1e-9 * kLame.mu);
      EXPECT_LT(piola(s, kLame).norm(), 1e-9 * kLame.mu);
    }
}

TEST(FemElement, StressIsTheGradientOfTheEnergy) {
  // Compared: P(F) against the central difference (ψ(F + hE_ij) − ψ(F − hE_ij))/2h, h = 1e-6, at random
  // F of strains up to 30 %. Tolerance 1e-6 relative to |P|: the difference's O(h²) error and rounding.
  std::mt19937 rng(kSeed + 1);
  for (const LawCase& c : kLaws)
    for (int k = 0; k < 10; ++k) {
      SCOPED_TRACE(std::string(c.name) + " sample " + std::to_string(k));
      const Mat3 F = rotation(Vec3(0.3, 1, 0.2), 0.7 * k) * (Mat3::Identity() + random_matrix(rng, 0.3));
      const Mat3 P = piola(element_state(c.law, F, c.b), kLame);
      EXPECT_LT((P - testing_support::energy_gradient_fd(c.law, F, c.b, kLame)).norm(), 1e-6 * P.norm());
    }
}

TEST(FemElement, StressDerivativeIsTheFiniteDifferenceOfTheStress) {
  // Compared: δP for a random δF against (P(F + hδF) − P(F − hδF))/2h, h = 1e-6; the co-rotational
  // δP includes the rotation's derivative. Tolerance 1e-6 relative to |δP|.
  std::mt19937 rng(kSeed + 2);
  for (const LawCase& c : kLaws)
    for (int k = 0; k < 10; ++k) {
      SCOPED_TRACE(std::string(c.name) + " sample " + std::to_string(k));
      const Mat3 F = rotation(Vec3(1, -0.4, 0.8), 0.9 * k) * (Mat3::Identity() + random_matrix(rng, 0.3));
      const Mat3 dF = random_matrix(rng, 1.0);
      const Mat3 dP = dpiola(element_state(c.law, F, c.b), dF, kLame);
      EXPECT_LT((dP - testing_support::piola_derivative_fd(c.law, F, dF, c.b, kLame)).norm(), 1e-6 * dP.norm());
    }
}

TEST(FemElement, SmallStrainsObeyHookesLaw) {
  // Compared: P at F = I + εH (ε = 1e-7) against Hooke's σ = 2μ sym(εH) + λ tr(εH) I. Tolerance 1e-5
  // relative: the laws' nonlinear terms are O(ε²)/O(ε) = 1e-7, plus rounding of ε-sized differences.
  std::mt19937 rng(kSeed + 3);
  const Mat3 H = random_matrix(rng, 1.0);
  const double eps = 1e-7;
  const Mat3 strain = 0.5 * eps * (H + H.transpose());
  const Mat3 hooke = 2 * kLame.mu * strain + kLame.lambda * strain.trace() * Mat3::Identity();
  for (const LawCase& c : kLaws) {
    SCOPED_TRACE(c.name);
    EXPECT_LT((piola(element_state(c.law, Mat3::Identity() + eps * H, c.b), kLame) - hooke).norm(),
              1e-5 * hooke.norm());
  }
}

TEST(FemElement, InvertedNeoHookeanElementHasNoEnergy) {
  // Compared: an inverted element (det F < 0) must be flagged, with infinite energy (the line search
  // rejects it), where the co-rotational law pushes back with a finite stress.
  Mat3 F = Mat3::Identity();
  F(2, 2) = -0.1;
  EXPECT_FALSE(element_state(FemLaw::NeoHookean, F).valid);
  EXPECT_TRUE(std::isinf(energy_density(element_state(FemLaw::NeoHookean, F), kLame)));
  const ElementState co = element_state(FemLaw::Corotational, F);
  EXPECT_TRUE(std::isfinite(energy_density(co, kLame)));
  EXPECT_GT(piola(co, kLame).norm(), 0.0);
}

// ---- on a mesh --------------------------------------------------------------------------------------------------

/// A block of wall voxels (5 mm) in a shell of viscera, meshed with cubes of 2 voxels, so some cubes
/// are partly filled (fractions and moduli vary per tetrahedron and the cube groups are uneven).
Mesh block_mesh(int n, int cube_voxels, bool shell = true) {
  Geometry g;
  const int pad = shell ? 1 : 0;
  g.dims = {n + 2 * pad, n + 2 * pad, n + 2 * pad};
  g.spacing_mm = Vec3::Constant(5.0);
  std::vector<Role> roles(g.voxel_count(), shell ? Role::Viscera : Role::Wall);
  for (int k = pad; k < n + pad; ++k)
    for (int j = pad; j < n + pad; ++j)
      for (int i = pad; i < n + pad; ++i) roles[g.linear_index(i, j, k)] = Role::Wall;
  MeshOptions o;
  o.cube_voxels = cube_voxels;
  o.model = MeshModel::Wall;
  Mesh m = build_mesh(VoxelRoles{g, roles.data(), nullptr}, o, [](Role, int) { return 60e3; });
  assign_material(m, MaterialOptions{});
  m.tet_poisson.assign(m.tets.size(), 0.45);
  return m;
}

struct FieldCase {
  MaterialModel model;
  bool mean_dilatation;
  double b;
  const char* name;
};
const FieldCase kFields[] = {{MaterialModel::FemCorotational, true, 0.0, "corotational, mean dilatation"},
                             {MaterialModel::FemCorotational, false, 0.0, "corotational, per tetrahedron"},
                             {MaterialModel::FemNeoHookean, true, 0.0, "neo-Hookean, mean dilatation"},
                             {MaterialModel::FemNeoHookean, false, 3.0, "Demiray, per tetrahedron"},
                             {MaterialModel::Msd, true, 0.0, "springs"},
                             {MaterialModel::Msd, true, 5.0, "stiffening springs"}};

ForceModel elastic_only(const FieldCase& c) {
  ForceModel fm;
  fm.material = c.model;
  fm.mean_dilatation = c.mean_dilatation;
  fm.stiffening = c.b;
  fm.damping = false;
  return fm;
}

TEST(FemField, ForcesAreMinusTheGradientOfTheElasticEnergy) {
  // Compared: each node's force against the central difference of the field's elastic energy (step
  // 1e-8 m) at a random state (nodes moved up to 0.5 mm of 10 mm cubes), with the cube-averaged
  // dilatation and without. Tolerance 1e-5 of the largest force: the difference's error and rounding.
  std::mt19937 rng(kSeed + 4);
  const Mesh m = block_mesh(4, 2);
  const std::vector<Vec3> x = perturbed(m, rng, 0.5e-3);
  for (const FieldCase& c : kFields) {
    SCOPED_TRACE(c.name);
    const ForceModel fm = elastic_only(c);
    auto field = make_force_field(m, fm);
    std::vector<Vec3> f;
    field->evaluate(fm, x, {}, f);
    const double worst =
        max_gradient_mismatch(x, f, 1e-8, [&](const std::vector<Vec3>& y) { return field->elastic_energy(fm, y); });
    EXPECT_LT(worst, 1e-5 * max_norm(f));
  }
}

TEST(FemField, StiffnessProductIsTheJacobianOfTheForces) {
  // Compared: K p at a random state against −(f(x + hp) − f(x − hp))/2h for a random p, h = 1e-7 m
  // (|p| ≤ 1). Tolerance 1e-6 of |K p|: the difference's O(h²) error and rounding. Also the diagonal
  // blocks the preconditioner uses: pᵀ K_nn p > 0 at every free node of a tetrahedral FEM.
  std::mt19937 rng(kSeed + 5);
  const Mesh m = block_mesh(4, 2);
  const std::vector<Vec3> x = perturbed(m, rng, 0.5e-3);
  std::vector<Vec3> dir(m.node_count());
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (auto& d : dir) d = Vec3(u(rng), u(rng), u(rng));
  for (const FieldCase& c : kFields) {
    SCOPED_TRACE(c.name);
    const ForceModel fm = elastic_only(c);
    auto field = make_force_field(m, fm);
    field->linearize(fm, x);
    std::vector<Vec3> kp, fp, fmn;
    field->stiffness_product(dir, kp);
    const double h = 1e-7;
    std::vector<Vec3> xp = x, xm = x;
    for (int64_t n = 0; n < m.node_count(); ++n) { xp[n] += h * dir[n]; xm[n] -= h * dir[n]; }
    field->evaluate(fm, xp, {}, fp);
    field->evaluate(fm, xm, {}, fmn);
    double worst = 0.0;
    for (int64_t n = 0; n < m.node_count(); ++n) worst = std::max(worst, (kp[n] + (fp[n] - fmn[n]) / (2 * h)).norm());
    EXPECT_LT(worst, 1e-6 * max_norm(kp));
    std::vector<Mat3> blocks;
    field->linearize(fm, m.rest_m);
    field->stiffness_diagonal(blocks);
    for (int64_t n = 0; n < m.node_count(); ++n) EXPECT_GT(dir[n].dot(blocks[n] * dir[n]), 0.0) << n;
  }
}

TEST(PressureStiffness, IsTheJacobianOfTheGasPressureOnAClosedSurface) {
  // The wall block inside its viscera shell: the cavity faces around it are closed on each side, so
  // the load is exactly P ∇V and its stiffness symmetric, and the per-load symmetric parts must sum to
  // the whole Jacobian. Compared: S p against −(f_p(x + hp) − f_p(x − hp))/2h at a random state,
  // h = 1e-7 m. Tolerance 1e-6 of |S p|: the difference's error and rounding. Then the symmetry,
  // qᵀ S p = pᵀ S q, to rounding (1e-12 relative).
  std::mt19937 rng(kSeed + 7);
  const Mesh m = block_mesh(4, 2);
  ASSERT_FALSE(m.load_tet.empty());
  const std::vector<Vec3> x = perturbed(m, rng, 0.5e-3);
  std::vector<Vec3> p(m.node_count()), q(m.node_count());
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (auto& d : p) d = Vec3(u(rng), u(rng), u(rng));
  for (auto& d : q) d = Vec3(u(rng), u(rng), u(rng));
  const double P = 1600.0;
  PressureStiffness ks;
  ks.linearize(m, x, P);
  std::vector<Vec3> sp(m.node_count(), Vec3::Zero()), sq(m.node_count(), Vec3::Zero());
  ks.add_product(p, sp);
  ks.add_product(q, sq);
  const double h = 1e-7;
  std::vector<Vec3> xp = x, xm = x;
  for (int64_t n = 0; n < m.node_count(); ++n) { xp[n] += h * p[n]; xm[n] -= h * p[n]; }
  const std::vector<Vec3> fp = pressure_forces(m, xp, P), fmn = pressure_forces(m, xm, P);
  double worst = 0.0;
  for (int64_t n = 0; n < m.node_count(); ++n) worst = std::max(worst, (sp[n] + (fp[n] - fmn[n]) / (2 * h)).norm());
  EXPECT_GT(max_norm(sp), 0.0);
  EXPECT_LT(worst, 1e-6 * max_norm(sp));
  double qsp = 0.0, psq = 0.0, scale = 0.0;
  for (int64_t n = 0; n < m.node_count(); ++n) {
    qsp += q[n].dot(sp[n]);
    psq += p[n].dot(sq[n]);
    scale += q[n].norm() * sp[n].norm();
  }
  EXPECT_LT(std::abs(qsp - psq), 1e-12 * scale);
}

TEST(FemField, RigidMotionOfTheMeshGivesNoForce) {
  // Compared: every node's force after a rotation by 2.5 rad and a 1 m translation of the whole mesh,
  // against zero. Tolerance 1e-9 of the forces of a 1 % stretch: rounding (both laws are frame-indifferent).
  const Mesh m = block_mesh(4, 2);
  const Mat3 Q = rotation(Vec3(0.2, -1, 0.6), 2.5);
  std::vector<Vec3> x(m.node_count()), stretched(m.node_count());
  for (int64_t n = 0; n < m.node_count(); ++n) {
    x[n] = Q * m.rest_m[n] + Vec3(1.0, -0.5, 0.25);
    stretched[n] = 1.01 * m.rest_m[n];
  }
  for (const FieldCase& c : kFields) {
    if (c.model == MaterialModel::Msd) continue;
    SCOPED_TRACE(c.name);
    const ForceModel fm = elastic_only(c);
    auto field = make_force_field(m, fm);
    std::vector<Vec3> f, fs;
    field->evaluate(fm, stretched, {}, fs);
    field->evaluate(fm, x, {}, f);
    EXPECT_LT(max_norm(f), 1e-9 * max_norm(fs));
  }
}

namespace {

/// The patch test's state: the boundary nodes of `m` held at x = A x₀ (hold set here), the interior
/// ones started off it by up to 0.3 mm at random; `interior` counts those.
std::vector<Vec3> patch_test_start(Mesh& m, const Mat3& A, std::mt19937& rng, int& interior) {
  Vec3 lo = Vec3::Constant(1e9), hi = Vec3::Constant(-1e9);
  for (const Vec3& p : m.rest_m) { lo = lo.cwiseMin(p); hi = hi.cwiseMax(p); }
  std::vector<Vec3> start(m.node_count());
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  interior = 0;
  for (int64_t n = 0; n < m.node_count(); ++n) {
    const Vec3& p = m.rest_m[n];
    const bool boundary = ((p - lo).cwiseAbs().minCoeff() < 1e-9) || ((hi - p).cwiseAbs().minCoeff() < 1e-9);
    m.hold[n] = boundary ? kHoldAll : 0;
    start[n] = A * p + (boundary ? Vec3::Zero() : Vec3(0.3e-3 * Vec3(u(rng), u(rng), u(rng))));
    interior += !boundary;
  }
  return start;
}

}  // namespace

TEST(FemField, PatchTestReproducesAUniformStrainExactly) {
  // The patch test: the boundary nodes of a solid block held at x = A x₀ (a uniform strain of up to 5 %
  // with a rotation), the interior nodes started off it at random; Newton must put every interior node
  // on A x₀. Compared: interior positions against A x₀, on the CPU and on every OpenCL device.
  // Tolerance on the CPU 1e-9 m (of 5 mm cubes), where the solver's residual tolerance 1e-10 leaves
  // sub-nanometre errors; on a device (float32) 1e-7 m to a residual of 1e-3 (this residual is relative
  // to the forces of a 0.1 % strain, so float rounding floors it near 1e-4): the rounding of
  // millimetre displacements. A scheme that fails the patch test is off by micrometres or more.
  std::mt19937 rng(kSeed + 6);
  Mesh m = block_mesh(4, 1, /*shell=*/false);
  const Mat3 A = rotation(Vec3(1, 1, 0), 0.3) * (Mat3::Identity() + random_matrix(rng, 0.05));
  int interior = 0;
  const std::vector<Vec3> start = patch_test_start(m, A, rng, interior);
  ASSERT_GT(interior, 20);
  Progress::set_enabled(false);
  for (const std::string& device : testing_support::cpu_and_opencl_device_specs())
    for (const FieldCase& c : kFields) {
      if (c.model == MaterialModel::Msd) continue;
      SCOPED_TRACE(std::string(c.name) + " on " + device);
      SolveOptions o;
      o.method = SolverMethod::Newton;
      o.forces = elastic_only(c);
      o.residual_tolerance = device == "cpu" ? 1e-10 : 1e-3;
      o.progress = false;
      std::shared_ptr<ocl::Context> ctx;
      if (device != "cpu") ctx = ocl::Context::shared(ocl::parse_device_spec(device));
      const SolveResult r = solve_on_device(ctx.get(), m, o, start);
      EXPECT_TRUE(r.converged) << r.stop_reason << ", residual " << r.residual;
      double worst = 0.0;
      for (int64_t n = 0; n < m.node_count(); ++n) worst = std::max(worst, (r.x[n] - A * m.rest_m[n]).norm());
      std::printf("%s on %s: %lld iterations, worst %.2g m\n", c.name, device.c_str(), (long long)r.steps, worst);
      EXPECT_LT(worst, device == "cpu" ? 1e-9 : 1e-7);
    }
}

TEST(FemField, PatchTestHoldsOnCubesOfPerAxisVoxels) {
  // The patch test above on a lattice whose cubes count different voxels per axis (core/cube_voxels.h):
  // 2.5 × 2.5 × 5 mm voxels in cubes of 2 × 2 × 1, so 5 mm cubes, 4 per axis, the boundary held at
  // x = A x₀ and the interior started off it at random. Compared on the CPU: interior positions against
  // A x₀, tolerance 1e-9 m as above (residual 1e-10). A lattice placed by one L on every axis, or sample
  // points of the wrong cube size, would still fail it by the random start's 0.3 mm.
  std::mt19937 rng(kSeed + 16);
  Geometry g;
  g.dims = {8, 8, 4};
  g.spacing_mm = Vec3(2.5, 2.5, 5.0);
  std::vector<Role> roles(g.voxel_count(), Role::Wall);
  MeshOptions mo;
  mo.cube_voxels = CubeVoxels(2, 2, 1);
  mo.model = MeshModel::Wall;
  Mesh m = build_mesh(VoxelRoles{g, roles.data(), nullptr}, mo, [](Role, int) { return 60e3; });
  assign_material(m, MaterialOptions{});
  m.tet_poisson.assign(m.tets.size(), 0.45);
  ASSERT_EQ(m.cubes, (std::array<int64_t, 3>{4, 4, 4}));
  const Mat3 A = rotation(Vec3(1, 0, 1), 0.2) * (Mat3::Identity() + random_matrix(rng, 0.05));
  Vec3 lo = Vec3::Constant(1e9), hi = Vec3::Constant(-1e9);
  for (const Vec3& p : m.rest_m) { lo = lo.cwiseMin(p); hi = hi.cwiseMax(p); }
  EXPECT_NEAR((hi - lo).minCoeff(), 20e-3, 1e-12);
  EXPECT_NEAR((hi - lo).maxCoeff(), 20e-3, 1e-12);
  int interior = 0;
  const std::vector<Vec3> start = patch_test_start(m, A, rng, interior);
  ASSERT_EQ(interior, 27);
  Progress::set_enabled(false);
  for (const FieldCase& c : kFields) {
    if (c.model == MaterialModel::Msd) continue;
    SCOPED_TRACE(c.name);
    SolveOptions o;
    o.method = SolverMethod::Newton;
    o.forces = elastic_only(c);
    o.residual_tolerance = 1e-10;
    o.progress = false;
    const SolveResult r = solve_on_device(nullptr, m, o, start);
    EXPECT_TRUE(r.converged) << r.stop_reason << ", residual " << r.residual;
    double worst = 0.0;
    for (int64_t n = 0; n < m.node_count(); ++n) worst = std::max(worst, (r.x[n] - A * m.rest_m[n]).norm());
    EXPECT_LT(worst, 1e-9);
  }
}

TEST(FireMasses, BoundEveryModeOfTheStiffnessAtRest) {
  // FIRE's step control assumes ω² ≤ 2 for its fictitious masses (solve_static_fire.cpp). Compared:
  // the largest eigenvalue of M^-1/2 K M^-1/2 at rest, by 300 power iterations (the block in its
  // shell, nothing held, every field), against 2 (Gershgorin's bound), and above 0.1 (not loose by
  // orders of magnitude, which would make FIRE needlessly slow).
  const Mesh m = block_mesh(4, 2);
  for (const FieldCase& c : kFields) {
    SCOPED_TRACE(c.name);
    const ForceModel fm = elastic_only(c);
    auto field = make_force_field(m, fm);
    const std::vector<double> mass = field->fire_masses(fm);
    field->linearize(fm, m.rest_m);
    std::vector<Vec3> y(m.node_count(), Vec3::Ones()), ky;
    double lambda = 0.0;
    for (int it = 0; it < 300; ++it) {
      std::vector<Vec3> p(m.node_count());
      for (int64_t n = 0; n < m.node_count(); ++n) p[n] = y[n] / std::sqrt(mass[n]);
      field->stiffness_product(p, ky);
      double norm = 0.0;
      for (int64_t n = 0; n < m.node_count(); ++n) {
        y[n] = ky[n] / std::sqrt(mass[n]);
        norm += y[n].squaredNorm();
      }
      norm = std::sqrt(norm);
      lambda = norm;   // |A y| for |y| = 1 (y was normalised below on the previous pass)
      for (auto& v : y) v /= norm;
    }
    std::printf("%s: largest omega^2 %.3f\n", c.name, lambda);
    EXPECT_GT(lambda, 0.1);   // the bound is not loose by orders of magnitude
    EXPECT_LE(lambda, 2.0);
  }
}

/// The largest distance between two solutions' nodes, and the largest move of the first from rest (m).
struct Apart {
  double worst = 0.0, moved = 0.0;
};
Apart apart(const Mesh& m, const SolveResult& a, const SolveResult& b) {
  Apart d;
  for (int64_t n = 0; n < m.node_count(); ++n) {
    d.worst = std::max(d.worst, (a.x[n] - b.x[n]).norm());
    d.moved = std::max(d.moved, (a.x[n] - m.rest_m[n]).norm());
  }
  return d;
}

TEST(StaticSolvers, FireAndNewtonReachTheSameEquilibriumForEveryField) {
  // Newton against FIRE (the static solver every test of solvers checks), each with the field's own
  // forces, stiffness and FIRE masses, on the block in its shell under 10 mmHg, both to a residual of
  // 1e-9: the springs (with and without stiffening) and the finite elements. Compared: every node's
  // position. Tolerance 1e-8 m: both residuals leave nanometre errors (displacements ~0.1 mm); a wrong
  // stiffness still converges (the line search keeps it safe) but a wrong force would not agree.
  Progress::set_enabled(false);
  const Mesh m = block_mesh(4, 2);
  for (const FieldCase& c : kFields) {
    SCOPED_TRACE(c.name);
    SolveOptions o;
    o.forces = elastic_only(c);
    o.forces.pressure_pa = 1333.2;
    o.residual_tolerance = 1e-9;
    o.max_steps = 400000;
    o.progress = false;
    o.method = SolverMethod::Static;
    const SolveResult fire = solve(m, o);
    o.method = SolverMethod::Newton;
    const SolveResult newton = solve(m, o);
    ASSERT_TRUE(fire.converged) << fire.stop_reason;
    ASSERT_TRUE(newton.converged) << newton.stop_reason;
    const Apart d = apart(m, fire, newton);
    std::printf("%s: FIRE %lld steps, Newton %lld iterations (%lld CG); largest move %.3g mm, difference %.2g m\n",
                c.name, (long long)fire.steps, (long long)newton.steps, (long long)newton.inner_iterations,
                1e3 * d.moved, d.worst);
    EXPECT_GT(d.moved, 1e-5);
    EXPECT_LT(d.worst, 1e-8);
  }
}

TEST(StaticSolvers, SchemesBuiltOnTheSpringsRefuseTheFiniteElements) {
  // The explicit, Newmark and 2004 schemes take their step, dampers or stiffness sums from the
  // springs: asked to solve finite elements they must refuse (InputError naming the model), not
  // quietly solve the springs or run an unstable step. The springs themselves still solve.
  Progress::set_enabled(false);
  const Mesh m = block_mesh(3, 2);
  for (SolverMethod method : {SolverMethod::Explicit, SolverMethod::Newmark, SolverMethod::Kitasaka2004}) {
    SCOPED_TRACE(enum_name(method));
    SolveOptions o;
    o.method = method;
    o.max_steps = 20;
    o.progress = false;
    o.forces.pressure_pa = 1333.2;
    o.forces.material = MaterialModel::FemCorotational;
    try {
      solve(m, o);
      ADD_FAILURE() << "solved finite elements";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("fem-corotational"), std::string::npos) << e.what();
    }
    o.forces.material = MaterialModel::Msd;
    EXPECT_NO_THROW(solve(m, o));
  }
}

TEST(ImplicitEuler, SettlesAtNewtonsEquilibriumWithStepsFarBeyondTheExplicitBound) {
  // Backward Euler (Bano's dynamic scheme) on the block in its shell under 10 mmHg ramped over 50 ms,
  // with a step 100 times the explicit schemes' stability bound, for the springs and both FEM laws.
  // Compared: where it comes to rest (residual 1e-6, speed 1e-6 m/s) against Newton's equilibrium.
  // Tolerance 1e-3 of the largest displacement: what a residual of 1e-6 and that speed leave. An
  // explicit scheme at this step diverges within a few steps.
  Progress::set_enabled(false);
  const Mesh m = block_mesh(4, 2);
  for (const FieldCase& c : kFields) {
    if (c.b != 0.0 || !c.mean_dilatation) continue;
    SCOPED_TRACE(c.name);
    SolveOptions o;
    o.forces = elastic_only(c);
    o.forces.pressure_pa = 1333.2;
    o.residual_tolerance = 1e-6;
    o.velocity_tolerance_m_s = 1e-6;
    o.ramp_s = 0.05;
    o.max_steps = 20000;
    o.progress = false;
    o.method = SolverMethod::Newton;
    const SolveResult newton = solve(m, o);
    o.method = SolverMethod::ImplicitEuler;
    o.dt_s = 100.0 * stable_time_step(m, false);
    const SolveResult euler = solve(m, o);
    ASSERT_TRUE(newton.converged) << newton.stop_reason;
    ASSERT_TRUE(euler.converged) << euler.stop_reason;
    const Apart d = apart(m, newton, euler);
    std::printf("%s: implicit Euler %lld steps of %.3g ms (%lld CG), largest move %.3g mm, from Newton %.2g m\n",
                c.name, (long long)euler.steps, 1e3 * euler.dt_s, (long long)euler.inner_iterations, 1e3 * d.moved,
                d.worst);
    EXPECT_GT(d.moved, 1e-5);
    EXPECT_LT(d.worst, 1e-3 * d.moved);
  }
}

TEST(FemLame, HollowSphereMatchesLamesClosedFormAndConverges) {
  // Compared: the mean radial displacement on the true spheres r = a and r = b of Lamé's sphere (a = 50,
  // b = 100 mm, E = 60 kPa, voxels a quarter of the cube, the mesh's field evaluated there) against the
  // closed form with the nominal moduli, at 10 and 5 mm cubes, one placement, for both FEM laws with
  // the cube-averaged dilatation, at ν = 0.25 and 0.45. Tolerances, the project's (docs/fem.md): within 3 % at 5 mm,
  // and converging at first order or better, i.e. the error at 5 mm at most half that at 10 mm
  // (measured, four placements: −2.4/−1.5 → −0.6/−0.4 % at ν 0.25, −3.5/−3.2 → −0.9/−0.8 % at 0.45,
  // inner/outer, co-rotational; an observed order of about 2, as linear elements' displacements converge).
  Progress::set_enabled(false);
  for (MaterialModel model : {MaterialModel::FemCorotational, MaterialModel::FemNeoHookean})
    for (double nu : {0.25, 0.45}) {
      SCOPED_TRACE(std::string(enum_name(model)) + " nu " + std::to_string(nu));
      LameResult at[2];
      for (int i = 0; i < 2; ++i) {
        LameOptions o;
        o.model = model;
        o.poisson = nu;
        o.cube_mm = i == 0 ? 10.0 : 5.0;
        o.placements = 1;
        at[i] = validate_lame_sphere(o);
        std::printf("%s nu %.2f, cube %.0f mm: inner %+.2f %%, outer %+.2f %%\n", enum_name(model), nu, o.cube_mm,
                    100 * at[i].rel_error_inner, 100 * at[i].rel_error_outer);
      }
      EXPECT_LE(std::abs(at[1].rel_error_inner), 0.03);
      EXPECT_LE(std::abs(at[1].rel_error_outer), 0.03);
      EXPECT_LE(std::abs(at[1].rel_error_inner), 0.5 * std::abs(at[0].rel_error_inner));
      EXPECT_LE(std::abs(at[1].rel_error_outer), 0.5 * std::abs(at[0].rel_error_outer));
    }
}

TEST(FemLame, EveryDeviceGivesTheCpusSphere) {
  // Lamé's sphere at 10 mm cubes (ν = 0.45, one placement) solved on every OpenCL device (float32)
  // and on the CPU (double), both laws, to a residual of 1e-5. Compared: the surface-mean inner and
  // outer displacements, device against CPU. Tolerance 1e-4 relative: float rounding of the forces
  // and the residual's share of a millimetre; a wrong element, group or load on the device is off by
  // per cents. The CPU's own distance to the closed form is the test above.
  Progress::set_enabled(false);
  for (const std::string& device : testing_support::opencl_device_specs())
    for (MaterialModel model : {MaterialModel::FemCorotational, MaterialModel::FemNeoHookean}) {
      SCOPED_TRACE(std::string(enum_name(model)) + " on " + device);
      LameOptions o;
      o.model = model;
      o.poisson = 0.45;
      o.cube_mm = 10.0;
      o.placements = 1;
      o.residual_tolerance = 1e-5;
      const LameResult cpu = validate_lame_sphere(o);
      o.device = device;
      const LameResult dev = validate_lame_sphere(o);
      std::printf("%s on %s: inner %.6f / %.6f mm, outer %.6f / %.6f mm (device / cpu), %lld / %lld iterations\n",
                  enum_name(model), device.c_str(), dev.u_inner_mm, cpu.u_inner_mm, dev.u_outer_mm, cpu.u_outer_mm,
                  (long long)dev.steps, (long long)cpu.steps);
      EXPECT_NEAR(dev.u_inner_mm, cpu.u_inner_mm, 1e-4 * cpu.u_inner_mm);
      EXPECT_NEAR(dev.u_outer_mm, cpu.u_outer_mm, 1e-4 * cpu.u_outer_mm);
    }
}

}  // namespace
}  // namespace pneumo
