#pragma once
// Tissue colours from published optical properties (docs/rendering.md "Tissue colours"), so that the
// laparoscopic preset's flesh tones are computed, not picked by eye. The chain, each step a
// published model:
//  1. absorption μa(λ) = B·S·μa,oxy(λ) + B·(1−S)·μa,deoxy(λ) + W·μa,water(λ) + F·μa,fat(λ)
//     + ln 10 · εβC(λ) · CβC (Jacques 2013, Phys. Med. Biol. 58 R37, Eq. 12, with its yellow
//     pigment β-carotene), whole blood at 150 g/l haemoglobin (2326 µM of tetramer, 64 500 g/mol):
//     μa,blood = ln 10 · ε(λ) · 2326 µM;
//  2. reduced scattering μs′(λ) = a·(λ / 500 nm)^−b (ibid., Eq. 1);
//  3. the diffuse reflectance of a thick tissue: the transport equation's answer for its albedo
//     μs′/(μa+μs′) (render/tissue_reflectance.h: Monte Carlo, tabulated; g = 0.9, n = 1.4);
//  4. the camera: tristimulus values under CIE D65 with the CIE 1931 2° observer, white-balanced
//     (a perfect white reflector gives display white, as a laparoscope's camera is balanced on a
//     white target before each case), sRGB primaries and transfer curve (IEC 61966-2-1).
// The surface's own gloss (the Fresnel reflection, about 3 % at n = 1.4) is not in R: the ray
// caster adds it as its specular highlight.
#include <functional>

#include "core/geometry.h"
#include "render/spectral_tables.h"
#include "render/tissue_reflectance.h"

namespace pneumo {

/// A tissue's optical make-up: volume fractions (0 to 1) and its scattering power law.
struct TissueOptics {
  double blood = 0.0;             // B: volume fraction of whole blood
  double saturation = 0.0;        // S: haemoglobin oxygen saturation
  double water = 0.0;             // W
  double fat = 0.0;               // F
  double beta_carotene_um = 0.0;  // β-carotene, µmol per litre of tissue
  double scatter_a_per_cm = 0.0;  // μs′ at 500 nm, cm⁻¹
  double scatter_b = 0.0;         // the power law's exponent
};

inline constexpr double kWholeBloodHaemoglobinMicroMolar = 150.0 / 64500.0 * 1e6;

/// μa and μs′ in mm⁻¹ at one sample of the table (steps 1 and 2).
double absorption_per_mm(const TissueOptics& t, const SpectralSample& s);
double reduced_scattering_per_mm(const TissueOptics& t, double nm);

/// Step 4's first half: CIE XYZ of a reflectance spectrum under D65, Y of the perfect white = 1.
Vec3 xyz_under_d65(const std::function<double(const SpectralSample&)>& reflectance);

/// Step 4's second half: XYZ (D65, Y of white = 1) to display sRGB in [0, 1], white-balanced so
/// that the perfect white reflector gives (1, 1, 1); components outside the gamut are clamped.
Vec3 display_srgb(const Vec3& xyz);

/// CIE 1976 L*a*b* of XYZ against the perfect white under D65 (for comparing with measured colours).
Vec3 cielab(const Vec3& xyz);

/// The whole chain: the tissue's reflectance spectrum, its XYZ, its display colour.
Vec3 tissue_xyz(const TissueOptics& t);
Vec3 tissue_srgb(const TissueOptics& t);

/// The tissues the laparoscopic preset colours, each with its published make-up (tissue_colour.cpp
/// says where each number was published and what was assumed).
enum class Tissue { Adipose, Muscle, Liver, Bowel, Pancreas, Kidney };
const TissueOptics& tissue_optics(Tissue t);

}  // namespace pneumo
