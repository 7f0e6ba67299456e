// The Levenberg–Marquardt shift of Newton's linear solve (conjugate_gradients.h): on an indefinite
// matrix CG meets non-positive curvature, and the shift σ grows tenfold from 10⁻³ until A + σD is
// positive definite. Compared against a 2-node matrix A = [[1, 2], [2, 1]] ⊗ I₃ (eigenvalues 3 and
// −1, diagonal blocks D = I): the first σ that makes A + σD positive definite in the sequence
// 10⁻³, 10⁻², … is 10 (at σ = 1 an eigenvalue is 0), so the solve must end with σ = 10 and a step
// that solves (A + 10 I) d = b to CG's tolerance η (checked to 2η); on a positive definite A it
// must not shift at all.
#include <gtest/gtest.h>

#include "solve/conjugate_gradients.h"

namespace pneumo {
namespace {

Mesh two_free_nodes() {
  Mesh m;
  m.rest_m = {Vec3::Zero(), Vec3::UnitX()};
  m.hold = {0, 0};
  return m;
}

TEST(ConjugateGradients, TheShiftGrowsUntilTheMatrixIsPositive) {
  const Mesh m = two_free_nodes();
  for (double off : {2.0, 0.5}) {   // indefinite, then positive definite (eigenvalues 1.5, 0.5)
    SCOPED_TRACE("off-diagonal " + std::to_string(off));
    const LinearOperator A = [&](const std::vector<Vec3>& p, std::vector<Vec3>& y) {
      y = {p[0] + off * p[1], off * p[0] + p[1]};
    };
    const std::vector<Mat3> blocks(2, Mat3::Identity()), precond(2, Mat3::Identity());
    const std::vector<Vec3> b = {Vec3(1, -2, 0.5), Vec3(0.3, 1, -1)};
    Shift shift;
    std::vector<Vec3> d;
    const double eta = 1e-8;
    const CgOutcome cg = shifted_conjugate_gradients(m, A, blocks, precond, b, eta, 100, shift, d);
    EXPECT_FALSE(cg.negative_curvature);
    EXPECT_EQ(shift.sigma, off > 1.0 ? 10.0 : 0.0);
    std::vector<Vec3> ad;
    A(d, ad);
    double r2 = 0, b2 = 0;
    for (int n = 0; n < 2; ++n) {
      r2 += (b[n] - ad[n] - shift.sigma * d[n]).squaredNorm();
      b2 += b[n].squaredNorm();
    }
    EXPECT_LE(std::sqrt(r2), 2 * eta * std::sqrt(b2));
  }
}

}  // namespace
}  // namespace pneumo
