// The fibre term of the finite elements (solve/fem_element.h) and the wall's fibre directions
// (mesh/wall_fibres.h) against truths computed here: the stress is the energy's gradient and its
// derivative the stress's finite difference with fibres in tension, fibres carry nothing in
// compression or under a rotation, a uniaxial stretch along and across them follows the closed form of
// an incompressible neo-Hookean matrix with fibres, and the wall's fibres run round the body.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "fem_test_support.h"
#include "mesh/wall_fibres.h"
#include "solve/fem_element.h"

namespace pneumo {
namespace {

const uint32_t kSeed = 20261207u;

TetMaterial with_fibre(TetMaterial m, const Vec3& a, double k1_over_mu, double k2) {
  m.fibre = a.normalized();
  m.fibre_k1_pa = k1_over_mu * m.mu;
  m.fibre_k2 = k2;
  return m;
}

using testing_support::random_matrix;

struct Case {
  FemLaw law;
  double b, k2;
  const char* name;
};
const Case kCases[] = {{FemLaw::Corotational, 0.0, 0.0, "corotational, quadratic fibres"},
                       {FemLaw::NeoHookean, 0.0, 0.0, "neo-Hookean, quadratic fibres"},
                       {FemLaw::NeoHookean, 4.0, 3.0, "Demiray b=4, exponential fibres k2=3"}};

TEST(FemFibres, StressIsTheGradientOfTheEnergyAndItsDerivativeTheStresssDifference) {
  // Compared: P(F) against central differences of ψ (h = 1e-6), and δP against central differences of P,
  // at random F of strains up to 30 % about a random fibre; samples whose fibre lies within 1e-4 of
  // I₄ = 1 are skipped (the tension switch's kink). Tolerance 1e-6 relative: O(h²) and rounding.
  std::mt19937 rng(kSeed);
  const TetMaterial matrix = TetMaterial::from_young_poisson(60e3, 0.45);
  int tension = 0, compression = 0;
  for (const Case& c : kCases)
    for (int k = 0; k < 24; ++k) {
      SCOPED_TRACE(std::string(c.name) + " sample " + std::to_string(k));
      const TetMaterial m = with_fibre(matrix, Vec3(random_matrix(rng, 1.0).col(0)), 0.67 + k % 3, c.k2);
      const Mat3 F = Mat3::Identity() + random_matrix(rng, 0.3);
      const double i4 = (F * m.fibre).squaredNorm();
      if (std::abs(i4 - 1.0) < 1e-4) continue;
      (i4 > 1.0 ? tension : compression) += 1;
      const ElementState s = element_state(c.law, F, c.b);
      const Mat3 P = piola(s, m);
      EXPECT_LT((P - testing_support::energy_gradient_fd(c.law, F, c.b, m)).norm(), 1e-6 * P.norm());
      const Mat3 dF = random_matrix(rng, 1.0);
      const Mat3 dP = dpiola(s, dF, m);
      EXPECT_LT((dP - testing_support::piola_derivative_fd(c.law, F, dF, c.b, m)).norm(), 1e-6 * dP.norm());
    }
  EXPECT_GT(tension, 10);       // both branches were sampled
  EXPECT_GT(compression, 10);
}

TEST(FemFibres, FibresCarryNothingInCompressionOrUnderARotation) {
  // Compared: with fibres along x, the stress of F = diag(0.9, 1.05, 1.05) (fibres shortened) and the
  // energy and stress of a rotation by 2 rad, against the matrix alone. Tolerance 1e-9 of μ: rounding.
  const TetMaterial matrix = TetMaterial::from_young_poisson(60e3, 0.45);
  const TetMaterial m = with_fibre(matrix, Vec3::UnitX(), 0.67, 3.0);
  const Mat3 Q = Eigen::AngleAxisd(2.0, Vec3(1, 2, -0.5).normalized()).toRotationMatrix();
  for (FemLaw law : {FemLaw::Corotational, FemLaw::NeoHookean}) {
    const ElementState shortened = element_state(law, Vec3(0.9, 1.05, 1.05).asDiagonal().toDenseMatrix(), 0.0);
    EXPECT_LT((piola(shortened, m) - piola(shortened, matrix)).norm(), 1e-9 * matrix.mu);
    const ElementState rotated = element_state(law, Q, 0.0);
    EXPECT_LT(std::abs(energy_density(rotated, m)), 1e-9 * matrix.mu);
    EXPECT_LT(piola(rotated, m).norm(), 1e-9 * matrix.mu);
  }
}

// The nominal stress P₁₁ of uniaxial stress at stretch λ along x: the lateral stretches found by Newton
// on P₂₂ = P₃₃ = 0 (F diagonal: P is diagonal for a fibre along a coordinate axis).
double uniaxial_nominal_stress(const TetMaterial& m, double lambda) {
  Vec3 s(lambda, 1.0 / std::sqrt(lambda), 1.0 / std::sqrt(lambda));
  for (int it = 0; it < 60; ++it) {
    const auto lateral = [&](const Vec3& st) {
      const Mat3 P = piola(element_state(FemLaw::NeoHookean, st.asDiagonal().toDenseMatrix(), 0.0), m);
      return Eigen::Vector2d(P(1, 1), P(2, 2));
    };
    const Eigen::Vector2d r = lateral(s);
    if (r.norm() < 1e-10 * m.mu) break;
    Eigen::Matrix2d J;
    for (int j = 0; j < 2; ++j) {
      Vec3 sp = s;
      sp[1 + j] += 1e-7;
      J.col(j) = (lateral(sp) - r) / 1e-7;
    }
    const Eigen::Vector2d d = J.fullPivLu().solve(-r);
    s[1] += d[0];
    s[2] += d[1];
  }
  return piola(element_state(FemLaw::NeoHookean, s.asDiagonal().toDenseMatrix(), 0.0), m)(0, 0);
}

TEST(FemFibres, UniaxialStretchAlongAndAcrossTheFibresFollowsTheClosedForm) {
  // Compared: the nominal stress of uniaxial stress at λ = 1.05 … 1.3 with ν = 0.4999 against the
  // incompressible closed forms (Holzapfel 2000 §6.5 for the matrix; the fibre term of fem_element.h)
  //   along the fibres:  P = μ(λ − λ⁻²) + 2ψ'(λ²) λ,   ψ'(I₄) = k₁(I₄ − 1)e^{k₂(I₄−1)²},
  //   across them:       P = μ(λ − λ⁻²)   (the fibres shorten by λ^{-1/2} and carry nothing).
  // Tolerance 0.5 %: the compressible law at K/μ = 5000 departs from incompressibility by
  // O(σ/K) ≈ 0.05 %, and the fibre term, not split into isochoric and volumetric parts, by as much.
  // Then the ratio of the small-strain moduli (λ = 1.0005) against 1 + 4k₁/(3μ) = 1.893 for k₁ = 0.67μ,
  // the ratio Song 2006 measured across and along the wall, within 0.5 %.
  const TetMaterial matrix = TetMaterial::from_young_poisson(30e3, 0.4999);
  for (double k2 : {0.0, 2.0}) {
    const TetMaterial along = with_fibre(matrix, Vec3::UnitX(), 0.67, k2);
    const TetMaterial across = with_fibre(matrix, Vec3::UnitY(), 0.67, k2);
    for (double lambda : {1.05, 1.1, 1.2, 1.3}) {
      SCOPED_TRACE("k2 " + std::to_string(k2) + ", stretch " + std::to_string(lambda));
      const double e = lambda * lambda - 1.0;
      const double matrix_p = matrix.mu * (lambda - 1.0 / (lambda * lambda));
      const double fibre_p = 2.0 * along.fibre_k1_pa * e * std::exp(k2 * e * e) * lambda;
      EXPECT_NEAR(uniaxial_nominal_stress(along, lambda), matrix_p + fibre_p, 5e-3 * (matrix_p + fibre_p));
      EXPECT_NEAR(uniaxial_nominal_stress(across, lambda), matrix_p, 5e-3 * matrix_p);
    }
  }
  const double small = 1.0005;
  const TetMaterial along = with_fibre(matrix, Vec3::UnitX(), 0.67, 0.0);
  const TetMaterial across = with_fibre(matrix, Vec3::UnitY(), 0.67, 0.0);
  EXPECT_NEAR(uniaxial_nominal_stress(along, small) / uniaxial_nominal_stress(across, small), 1.0 + 4.0 * 0.67 / 3.0,
              5e-3 * 1.893);
}

// A ring of wall tetrahedra round the z axis at radius 0.1 m and one of viscera at its centre; one more
// wall tetrahedron the caller leaves without fibres (a lung's).
Mesh ring_mesh() {
  Mesh m;
  const double r = 0.1, s = 0.004;
  auto add_tet = [&](const Vec3& c, Part part) {
    const int32_t base = int32_t(m.rest_m.size());
    for (const Vec3& d : {Vec3(0, 0, 0), Vec3(s, 0, 0), Vec3(0, s, 0), Vec3(0, 0, s)}) m.rest_m.push_back(c + d);
    m.tets.push_back({base, base + 1, base + 2, base + 3});
    m.tet_part.push_back(part);
    m.tet_rest_volume_m3.push_back(s * s * s / 6.0);
    m.tet_young_pa.push_back(60e3);
    m.tet_poisson.push_back(0.45);
  };
  for (int k = 0; k < 16; ++k) {
    const double a = 2.0 * 3.14159265358979323846 * k / 16.0;
    add_tet(Vec3(r * std::cos(a) + 0.03, r * std::sin(a) - 0.02, 0.001), Part::Wall);   // axis at (0.03, −0.02)
  }
  add_tet(Vec3(0.03, -0.02, 0.001), Part::Viscera);
  add_tet(Vec3(0.03 + r, -0.02, 0.001), Part::Wall);
  return m;
}

TEST(WallFibres, RunRoundTheBodyInTheAxialPlane) {
  // Compared: each fibrous wall tetrahedron's fibre against ẑ × r̂, r̂ the unit radial from the body's
  // axis, which is the volume-weighted mean of all tetrahedra's centres in the slab (wall_fibres.h;
  // computed here from the 18 equal tetrahedra, 6 mm off the ring's centre because of the 18th);
  // |a₀| = 1 and a₀·ẑ = 0; the viscera's and the non-fibrous tetrahedron's against none; k₁ against
  // 0.67 μ. Tolerance 1e-9: rounding.
  Mesh m = ring_mesh();
  std::vector<uint8_t> fibrous(m.tets.size(), 1);
  fibrous[16] = 0;   // the viscera: the caller marks wall tetrahedra only
  fibrous[17] = 0;   // a lung's
  assign_wall_fibres(m, fibrous, 0.67, 1.5);
  std::vector<Vec3> centre(m.tets.size(), Vec3::Zero());
  Vec3 axis = Vec3::Zero();
  for (std::size_t t = 0; t < m.tets.size(); ++t) {
    for (int32_t n : m.tets[t]) centre[t] += 0.25 * m.rest_m[n];
    axis += centre[t] / double(m.tets.size());
  }
  EXPECT_GT(axis[0] - 0.03, 0.005);   // the 18th tetrahedron moves the axis; the rule must follow it
  EXPECT_EQ(m.fibre_k2, 1.5);
  for (int t = 0; t < 16; ++t) {
    const Vec3 radial = Vec3(centre[t][0] - axis[0], centre[t][1] - axis[1], 0.0).normalized();
    const Vec3 expected = Vec3::UnitZ().cross(radial);
    EXPECT_NEAR(m.tet_fibre[t].norm(), 1.0, 1e-12);
    EXPECT_NEAR(m.tet_fibre[t][2], 0.0, 1e-12);
    EXPECT_LT((m.tet_fibre[t] - expected).norm(), 1e-9) << "tetrahedron " << t;
    EXPECT_NEAR(m.tet_fibre_k1_pa[t], 0.67 * 60e3 / (2.0 * 1.45), 1e-9);
  }
  for (int t : {16, 17}) {
    EXPECT_EQ(m.tet_fibre[t].norm(), 0.0);
    EXPECT_EQ(m.tet_fibre_k1_pa[t], 0.0);
  }
}

}  // namespace
}  // namespace pneumo
