#pragma once
// What the finite elements' derivative checks share (test_fem.cpp, test_fem_fibres.cpp): central
// differences of the energy and of the stress of one element, and random matrices.
#include <random>

#include "solve/fem_element.h"

namespace pneumo::testing_support {

inline Mat3 random_matrix(std::mt19937& rng, double amplitude) {
  std::uniform_real_distribution<double> u(-amplitude, amplitude);
  Mat3 m;
  for (int i = 0; i < 9; ++i) m(i / 3, i % 3) = u(rng);
  return m;
}

/// (ψ(F + hE_ij) − ψ(F − hE_ij)) / 2h for every entry ij: what P = ∂ψ/∂F must equal, to O(h²).
inline Mat3 energy_gradient_fd(FemLaw law, const Mat3& F, double b, const TetMaterial& m, double h = 1e-6) {
  Mat3 fd;
  for (int i = 0; i < 9; ++i) {
    Mat3 Fp = F, Fm = F;
    Fp(i / 3, i % 3) += h;
    Fm(i / 3, i % 3) -= h;
    fd(i / 3, i % 3) = (energy_density(element_state(law, Fp, b), m) - energy_density(element_state(law, Fm, b), m)) / (2 * h);
  }
  return fd;
}

/// (P(F + h δF) − P(F − h δF)) / 2h: what δP must equal, to O(h²).
inline Mat3 piola_derivative_fd(FemLaw law, const Mat3& F, const Mat3& dF, double b, const TetMaterial& m, double h = 1e-6) {
  return (piola(element_state(law, F + h * dF, b), m) - piola(element_state(law, F - h * dF, b), m)) / (2 * h);
}

}  // namespace pneumo::testing_support
