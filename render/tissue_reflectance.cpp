#include "render/tissue_reflectance.h"

#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>

namespace pneumo {
namespace {

constexpr double kPi = 3.14159265358979323846;

// Unpolarised Fresnel reflectance from inside (index n) to outside (1) at cosine `cos_in`.
double fresnel_from_inside(double n, double cos_in) {
  const double sin_out = n * std::sqrt(std::max(0.0, 1.0 - cos_in * cos_in));
  if (sin_out >= 1.0) return 1.0;  // total internal reflection
  const double cos_out = std::sqrt(1.0 - sin_out * sin_out);
  const double rs = (n * cos_in - cos_out) / (n * cos_in + cos_out);
  const double rp = (n * cos_out - cos_in) / (n * cos_out + cos_in);
  return 0.5 * (rs * rs + rp * rp);
}

}  // namespace

ReflectanceEstimate monte_carlo_reflectance(double albedo, double g, double n, int64_t photons, uint64_t seed) {
  if (!(albedo > 0.0 && albedo <= 1.0) || !(g > -1.0 && g < 1.0) || !(n >= 1.0) || photons < 2)
    throw std::invalid_argument("monte_carlo_reflectance: albedo in (0, 1], |g| < 1, n >= 1, two photons or more");
  // Lengths in units of the transport mean free path: μs′ = a′, μa = 1 − a′, μs = μs′/(1 − g).
  const double mus = albedo / (1.0 - g), mua = 1.0 - albedo, mut = mus + mua;
  std::mt19937_64 rng(seed);
  auto uniform = [&] { return double(rng() >> 11) * 0x1.0p-53; };  // [0, 1), the same on every platform
  double sum = 0.0, sum_sq = 0.0;
  for (int64_t p = 0; p < photons; ++p) {
    double z = 0.0, ux = 0.0, uy = 0.0, uz = 1.0, w = 1.0, out = 0.0;
    for (;;) {
      const double step = -std::log(1.0 - uniform()) / mut;
      if (z + step * uz < 0.0) {                        // reaches the surface from inside
        if (uniform() >= fresnel_from_inside(n, -uz)) {  // leaves
          out = w;
          break;
        }
        const double rest = step + z / uz;               // the path left after the surface
        uz = -uz;
        z = rest * uz;
        continue;
      }
      z += step * uz;
      w *= mus / mut;                                    // the absorbed part stays behind
      if (w < 1e-4) {                                    // Russian roulette: unbiased
        if (uniform() < 0.1) w *= 10.0;
        else break;
      }
      double cos_t = 2.0 * uniform() - 1.0;              // Henyey-Greenstein's cosine
      if (g != 0.0) {
        const double f = (1.0 - g * g) / (1.0 - g + 2.0 * g * uniform());
        cos_t = (1.0 + g * g - f * f) / (2.0 * g);
      }
      const double sin_t = std::sqrt(std::max(0.0, 1.0 - cos_t * cos_t)), phi = 2.0 * kPi * uniform();
      const double cp = std::cos(phi), sp = std::sin(phi);
      if (std::fabs(uz) > 0.99999) {
        ux = sin_t * cp;
        uy = sin_t * sp;
        uz = uz > 0.0 ? cos_t : -cos_t;  // the new direction is measured from the old one
      } else {
        const double r = std::sqrt(1.0 - uz * uz);
        const double nx = sin_t * (ux * uz * cp - uy * sp) / r + ux * cos_t;
        const double ny = sin_t * (uy * uz * cp + ux * sp) / r + uy * cos_t;
        uz = -sin_t * cp * r + uz * cos_t;
        ux = nx;
        uy = ny;
      }
    }
    sum += out;
    sum_sq += out * out;
  }
  const double mean = sum / double(photons);
  const double var = std::max(0.0, sum_sq / double(photons) - mean * mean) / double(photons - 1);
  return {mean, std::sqrt(var)};
}

// monte_carlo_reflectance(1 − s²/3, kTissueAnisotropy, kTissueRefractiveIndex, N, 1000 + k) at
// s = k·√3/32, N = 50 000 photons for k = 1 to 3 (the slowest: packets scatter thousands of times
// before they leave), 200 000 for the rest; k = 0 (no absorption) returns everything, k = 32 (no
// scattering) nothing. tests/test_tissue_colour.cpp draws entries afresh and compares.
const double kReflectanceTable[kReflectanceTableSize] = {
    1, 0.854112, 0.737073, 0.639123, 0.553171, 0.481515, 0.418826, 0.367853, 0.320964, 0.283728,
    0.246803, 0.216542, 0.189671, 0.164949, 0.143374, 0.124260, 0.106133, 0.092792, 0.079772,
    0.067236, 0.056678, 0.047650, 0.039102, 0.031466, 0.025537, 0.019809, 0.015232, 0.011335,
    0.008219, 0.005327, 0.003140, 0.001432, 0.000000};
const double kReflectanceTableError[kReflectanceTableSize] = {
    0, 0.001204, 0.001492, 0.001613, 0.000828, 0.000827, 0.000807, 0.000781, 0.000750, 0.000716,
    0.000679, 0.000641, 0.000604, 0.000564, 0.000528, 0.000492, 0.000453, 0.000423, 0.000392,
    0.000358, 0.000329, 0.000301, 0.000271, 0.000242, 0.000218, 0.000191, 0.000166, 0.000144,
    0.000123, 0.000096, 0.000073, 0.000044, 0.000000};

double tissue_reflectance(double mua_per_mm, double musp_per_mm) {
  if (!(mua_per_mm >= 0.0) || !(musp_per_mm > 0.0))
    throw std::invalid_argument("tissue_reflectance needs mu_a >= 0 and mu_s' > 0");
  const double albedo = musp_per_mm / (mua_per_mm + musp_per_mm);
  const double s = std::sqrt(3.0 * (1.0 - albedo));
  const double x = s / std::sqrt(3.0) * (kReflectanceTableSize - 1);
  const int k = std::min(int(x), kReflectanceTableSize - 2);
  const double t = x - k;
  return (1.0 - t) * kReflectanceTable[k] + t * kReflectanceTable[k + 1];
}

}  // namespace pneumo
