#pragma once
// The diffuse reflectance of a thick tissue under broad white light (step 3 of render/tissue_colour.h):
// the fraction of light that enters a semi-infinite scattering medium and comes back out, as a
// function of its transport albedo a′ = μs′ / (μa + μs′), with Henyey-Greenstein scattering of
// anisotropy g and refractive index n inside (1 outside).
//
// Diffusion theory's closed form (Farrell, Patterson & Wilson 1992) is exact only as a′ → 1: blood
// makes tissue's blue and green strongly absorbing (at 540 nm a′ is 0.84 in muscle, 0.55 in bowel,
// 0.11 in liver), where it overstates the reflectance: 1.17 times the transport equation's at
// a′ = 0.90, 2.06 times at 0.53, 4.0 times at 0.06 (tests/test_tissue_colour.cpp). So the colours
// take the transport equation's answer, by Monte Carlo (the reference below, checked
// against Chandrasekhar's exact solution for isotropic scattering), tabulated once for tissue's
// g = 0.9 and n = 1.4 (Jacques 2013).
#include <cstdint>

namespace pneumo {

inline constexpr double kTissueAnisotropy = 0.9;
inline constexpr double kTissueRefractiveIndex = 1.4;

/// Monte Carlo reference: total diffuse reflectance of a semi-infinite medium for a collimated
/// beam entering at normal incidence (the specular reflection at entry excluded), `photons`
/// photon packets with implicit absorption and Russian roulette, Fresnel reflection (unpolarised)
/// where a packet meets the surface from inside. Deterministic for a seed. Returns {mean, standard
/// error}.
struct ReflectanceEstimate {
  double reflectance = 0.0;
  double standard_error = 0.0;
};
ReflectanceEstimate monte_carlo_reflectance(double albedo, double g, double n, int64_t photons, uint64_t seed);

/// The table: monte_carlo_reflectance(a′, 0.9, 1.4) at s = √(3(1 − a′)) = k·√3/32, k = 0 … 32,
/// interpolated linearly in s (the reflectance is smooth in s; it has a square-root cusp in a′).
inline constexpr int kReflectanceTableSize = 33;
extern const double kReflectanceTable[kReflectanceTableSize];
extern const double kReflectanceTableError[kReflectanceTableSize];  // the estimates' standard errors
double tissue_reflectance(double mua_per_mm, double musp_per_mm);

}  // namespace pneumo
