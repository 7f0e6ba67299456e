// The constitutive laws of fem_element.h.
#include "solve/fem_element.h"

#include <cmath>

#include <Eigen/SVD>

namespace pneumo {

namespace {

// [v]× · w = v × w.
Mat3 cross_matrix(const Vec3& v) {
  Mat3 m;
  m << 0, -v[2], v[1], v[2], 0, -v[0], -v[1], v[0], 0;
  return m;
}

// v with [v]× = the skew part's double, A − Aᵀ for A = RᵀδF (the axial vector of a skew matrix).
Vec3 axial_of_difference(const Mat3& A) {
  return Vec3(A(2, 1) - A(1, 2), A(0, 2) - A(2, 0), A(1, 0) - A(0, 1));
}

}  // namespace

Polar polar_decomposition(const Mat3& F) {
  Eigen::JacobiSVD<Mat3> svd(F, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Mat3 U = svd.matrixU(), V = svd.matrixV();
  Vec3 sigma = svd.singularValues();   // descending: the last is the smallest
  // Make U and V rotations; a reflection left over goes into the smallest singular value (an
  // inverted element keeps a proper rotation and a negative stretch).
  if (U.determinant() < 0.0) { U.col(2) *= -1.0; sigma[2] *= -1.0; }
  if (V.determinant() < 0.0) { V.col(2) *= -1.0; sigma[2] *= -1.0; }
  Polar p;
  p.R = U * V.transpose();
  p.S = V * sigma.asDiagonal() * V.transpose();
  p.V = V;
  p.sigma = sigma;
  return p;
}

ElementState element_state(FemLaw law, const Mat3& F, double b) {
  ElementState s;
  s.law = law;
  s.F = F;
  s.b = b;
  if (law == FemLaw::Corotational) {
    const Polar p = polar_decomposition(F);
    s.R = p.R;
    // (tr S · I − S) has the eigenvalues σ_j + σ_k in the basis V; a sum near zero (a flat element)
    // is floored at 10⁻⁶ keeping its sign, which bounds δR where the rotation is undefined.
    Vec3 inv;
    for (int i = 0; i < 3; ++i) {
      double sum = p.sigma.sum() - p.sigma[i];
      if (std::abs(sum) < 1e-6) sum = std::copysign(1e-6, sum);
      inv[i] = 1.0 / sum;
    }
    s.omega_inverse = p.V * inv.asDiagonal() * p.V.transpose();
    s.e = p.sigma.sum() - 3.0;
  } else {
    const double J = F.determinant();
    s.valid = J > 0.0 && std::isfinite(J);
    if (s.valid) {
      s.F_inverse_t = F.inverse().transpose();
      s.e = std::log(J);
      s.j23 = std::pow(J, -2.0 / 3.0);
      s.i1 = F.squaredNorm();
      s.exponential = b > 0.0 ? std::exp(b * (s.j23 * s.i1 - 3.0)) : 1.0;
    }
  }
  return s;
}

double volumetric_modulus(FemLaw law, const TetMaterial& m) {
  return law == FemLaw::Corotational ? m.lambda : m.lambda + 2.0 * m.mu / 3.0;
}

namespace {
// ∂Ī₁/∂F = J^{−2/3} (2F − ⅔ I₁ F⁻ᵀ).
Mat3 isochoric_i1_gradient(const ElementState& s) { return s.j23 * (2.0 * s.F - (2.0 / 3.0) * s.i1 * s.F_inverse_t); }
}  // namespace

namespace {

// The fibres' ψ_f, ψ' and ψ'' at I₄ (fem_element.h); all zero in compression (I₄ < 1) or without fibres.
struct FibreTerms {
  double energy = 0, d1 = 0, d2 = 0;
  Vec3 fa;   // F a₀
};
FibreTerms fibre_terms(const ElementState& s, const TetMaterial& m) {
  FibreTerms f;
  if (!(m.fibre_k1_pa > 0.0)) return f;
  f.fa = s.F * m.fibre;
  const double e = f.fa.squaredNorm() - 1.0;
  if (e < 0.0) return f;
  const double k1 = m.fibre_k1_pa, k2 = m.fibre_k2, x = k2 * e * e;
  const double ex = std::exp(x);
  f.energy = k2 > 0.0 ? k1 * std::expm1(x) / (2.0 * k2) : 0.5 * k1 * e * e;
  f.d1 = k1 * e * ex;
  f.d2 = k1 * (1.0 + 2.0 * x) * ex;
  return f;
}

double fibre_energy_density(const ElementState& s, const TetMaterial& m) { return fibre_terms(s, m).energy; }

Mat3 fibre_piola(const ElementState& s, const TetMaterial& m) {
  const FibreTerms f = fibre_terms(s, m);
  if (f.d1 == 0.0) return Mat3::Zero();
  return 2.0 * f.d1 * f.fa * m.fibre.transpose();
}

Mat3 fibre_dpiola(const ElementState& s, const Mat3& dF, const TetMaterial& m) {
  const FibreTerms f = fibre_terms(s, m);
  if (f.d2 == 0.0) return Mat3::Zero();
  const Vec3 dfa = dF * m.fibre;
  return (2.0 * f.d1 * dfa + 4.0 * f.d2 * f.fa.dot(dfa) * f.fa) * m.fibre.transpose();
}

}  // namespace

double deviatoric_energy_density(const ElementState& s, const TetMaterial& m) {
  if (s.law == FemLaw::Corotational) return m.mu * (s.F - s.R).squaredNorm() + fibre_energy_density(s, m);
  if (!s.valid) return INFINITY;
  const double bar_i1_minus_3 = s.j23 * s.i1 - 3.0;
  return m.mu * (s.b > 0.0 ? std::expm1(s.b * bar_i1_minus_3) / (2.0 * s.b) : 0.5 * bar_i1_minus_3) +
         fibre_energy_density(s, m);
}

Mat3 deviatoric_piola(const ElementState& s, const TetMaterial& m) {
  if (s.law == FemLaw::Corotational) return 2.0 * m.mu * (s.F - s.R) + fibre_piola(s, m);
  if (!s.valid) return Mat3::Constant(NAN);
  return 0.5 * m.mu * s.exponential * isochoric_i1_gradient(s) + fibre_piola(s, m);
}

Mat3 dilatation_gradient(const ElementState& s) {
  return s.law == FemLaw::Corotational ? s.R : s.F_inverse_t;
}

namespace {
// δR = R[ω]× (fem_element.h).
Mat3 corotational_drotation(const ElementState& s, const Mat3& dF) {
  const Vec3 omega = s.omega_inverse * axial_of_difference(s.R.transpose() * dF);
  return s.R * cross_matrix(omega);
}
}  // namespace

Mat3 deviatoric_dpiola(const ElementState& s, const Mat3& dF, const TetMaterial& m) {
  if (s.law == FemLaw::Corotational) return 2.0 * m.mu * (dF - corotational_drotation(s, dF)) + fibre_dpiola(s, dF, m);
  // δ(F⁻ᵀ) = −F⁻ᵀ δFᵀ F⁻ᵀ, δJ^{−2/3} = −⅔ J^{−2/3} F⁻ᵀ:δF, δI₁ = 2F:δF, δe^{b(Ī₁−3)} = b e^{b(Ī₁−3)} δĪ₁.
  const Mat3 g = isochoric_i1_gradient(s);
  const Mat3 d_inverse_t = -s.F_inverse_t * dF.transpose() * s.F_inverse_t;
  const double d_j23 = -(2.0 / 3.0) * s.j23 * s.F_inverse_t.cwiseProduct(dF).sum();
  const double d_i1 = 2.0 * s.F.cwiseProduct(dF).sum();
  const Mat3 dg = d_j23 / s.j23 * g +
                  s.j23 * (2.0 * dF - (2.0 / 3.0) * (d_i1 * s.F_inverse_t + s.i1 * d_inverse_t));
  const double d_exponential = s.b * s.exponential * g.cwiseProduct(dF).sum();
  return 0.5 * m.mu * (d_exponential * g + s.exponential * dg) + fibre_dpiola(s, dF, m);
}

Mat3 dilatation_dgradient(const ElementState& s, const Mat3& dF) {
  if (s.law == FemLaw::Corotational) return corotational_drotation(s, dF);
  return -s.F_inverse_t * dF.transpose() * s.F_inverse_t;
}

double energy_density(const ElementState& s, const TetMaterial& m) {
  return deviatoric_energy_density(s, m) + 0.5 * volumetric_modulus(s.law, m) * s.e * s.e;
}

Mat3 piola(const ElementState& s, const TetMaterial& m) {
  return deviatoric_piola(s, m) + volumetric_modulus(s.law, m) * s.e * dilatation_gradient(s);
}

Mat3 dpiola(const ElementState& s, const Mat3& dF, const TetMaterial& m) {
  const Mat3 G = dilatation_gradient(s);
  return deviatoric_dpiola(s, dF, m) +
         volumetric_modulus(s.law, m) * (G.cwiseProduct(dF).sum() * G + s.e * dilatation_dgradient(s, dF));
}

Mat3 edge_matrix(const Vec3& x0, const Vec3& x1, const Vec3& x2, const Vec3& x3) {
  Mat3 d;
  d.col(0) = x1 - x0;
  d.col(1) = x2 - x0;
  d.col(2) = x3 - x0;
  return d;
}

TetRest tet_rest(const Vec3& x0, const Vec3& x1, const Vec3& x2, const Vec3& x3) {
  const Mat3 dm = edge_matrix(x0, x1, x2, x3);
  return {dm.inverse(), dm.determinant() / 6.0};
}

std::array<Vec3, 4> nodal_forces(const Mat3& P, const TetRest& rest) {
  const Mat3 H = -rest.volume_m3 * P * rest.dm_inverse.transpose();
  return {Vec3(-(H.col(0) + H.col(1) + H.col(2))), Vec3(H.col(0)), Vec3(H.col(1)), Vec3(H.col(2))};
}

std::array<Vec3, 4> shape_gradients(const TetRest& rest) {
  const Mat3& D = rest.dm_inverse;
  return {Vec3(-(D.row(0) + D.row(1) + D.row(2)).transpose()), Vec3(D.row(0).transpose()), Vec3(D.row(1).transpose()),
          Vec3(D.row(2).transpose())};
}

}  // namespace pneumo
