#include "solve/conjugate_gradients.h"

#include <cmath>

#include "solve/solver_common.h"

namespace pneumo {

double dot(const std::vector<Vec3>& a, const std::vector<Vec3>& b) {
  double s = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) s += a[i].dot(b[i]);
  return s;
}

std::vector<Mat3> block_jacobi(const Mesh& m, const std::vector<Mat3>& blocks) {
  std::vector<Mat3> inv(blocks.size());
  for (std::size_t n = 0; n < blocks.size(); ++n) {
    Mat3 b = blocks[n];
    for (int a = 0; a < 3; ++a)
      if (m.hold[n] & (1 << a)) { b.row(a).setZero(); b.col(a).setZero(); b(a, a) = 1.0; }
    Mat3 i;
    bool ok = false;
    double det = 0.0;
    b.computeInverseAndDetWithCheck(i, det, ok);
    if (!ok || !(det > 0.0) || !i.allFinite()) {
      i.setZero();
      for (int a = 0; a < 3; ++a) i(a, a) = b(a, a) > 0.0 ? 1.0 / b(a, a) : 0.0;
    }
    for (int a = 0; a < 3; ++a)
      if (m.hold[n] & (1 << a)) { i.row(a).setZero(); i.col(a).setZero(); }
    inv[n] = i;
  }
  return inv;
}

CgOutcome conjugate_gradients(const Mesh& m, const LinearOperator& A, const std::vector<Mat3>& precond,
                              const std::vector<Vec3>& b, double eta, int max_iterations, std::vector<Vec3>& d) {
  const std::size_t N = b.size();
  CgOutcome out;
  std::vector<Vec3> r = b, z(N), p(N), ap;
  d.assign(N, Vec3::Zero());
  for (std::size_t n = 0; n < N; ++n) z[n] = precond[n] * r[n];
  p = z;
  double rz = dot(r, z);
  const double stop = eta * std::sqrt(dot(b, b));
  for (int it = 0; it < max_iterations; ++it) {
    A(p, ap);
    detail::apply_holds(m, ap);
    const double pap = dot(p, ap);
    if (!(pap > 0.0)) {
      out.negative_curvature = true;
      break;
    }
    const double a = rz / pap;
    for (std::size_t n = 0; n < N; ++n) { d[n] += a * p[n]; r[n] -= a * ap[n]; }
    out.iterations = it + 1;
    if (std::sqrt(dot(r, r)) <= stop) break;
    for (std::size_t n = 0; n < N; ++n) z[n] = precond[n] * r[n];
    const double rz_next = dot(r, z);
    const double beta = rz_next / rz;
    rz = rz_next;
    for (std::size_t n = 0; n < N; ++n) p[n] = z[n] + beta * p[n];
  }
  return out;
}

CgOutcome with_growing_shift(Shift& shift, const std::function<CgOutcome(double sigma)>& cg) {
  int iterations = 0;
  for (;;) {
    CgOutcome out = cg(shift.sigma);
    iterations += out.iterations;
    if (!out.negative_curvature || shift.sigma >= Shift::kMax) {
      out.iterations = iterations;
      return out;
    }
    shift.sigma = shift.sigma > 0.0 ? 10.0 * shift.sigma : Shift::kFirst;
  }
}

CgOutcome shifted_conjugate_gradients(const Mesh& m, const LinearOperator& A, const std::vector<Mat3>& blocks,
                                      const std::vector<Mat3>& precond, const std::vector<Vec3>& b, double eta,
                                      int max_iterations, Shift& shift, std::vector<Vec3>& d) {
  return with_growing_shift(shift, [&](double sigma) {
    const LinearOperator shifted = [&](const std::vector<Vec3>& p, std::vector<Vec3>& y) {
      A(p, y);
      if (sigma > 0.0)
        for (std::size_t n = 0; n < p.size(); ++n) y[n] += sigma * (blocks[n] * p[n]);
    };
    return conjugate_gradients(m, shifted, precond, b, eta, max_iterations, d);
  });
}

}  // namespace pneumo
