#include "render/tissue_colour.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace pneumo {

double absorption_per_mm(const TissueOptics& t, const SpectralSample& s) {
  const double blood = std::log(10.0) * kWholeBloodHaemoglobinMicroMolar *
                       (t.saturation * s.hbo2 + (1.0 - t.saturation) * s.hb);
  return t.blood * blood + t.water * s.water + t.fat * s.fat + std::log(10.0) * s.beta_carotene * t.beta_carotene_um;
}

double reduced_scattering_per_mm(const TissueOptics& t, double nm) {
  return 0.1 * t.scatter_a_per_cm * std::pow(nm / 500.0, -t.scatter_b);
}

Vec3 xyz_under_d65(const std::function<double(const SpectralSample&)>& reflectance) {
  // Sums over the 5 nm samples (CIE 015:2018 §7.1's summation); the common step cancels.
  Vec3 xyz = Vec3::Zero();
  double white_y = 0.0;
  for (const SpectralSample& s : kSpectralTable) {
    const double e = s.d65 * reflectance(s);
    xyz += e * Vec3(s.x_bar, s.y_bar, s.z_bar);
    white_y += s.d65 * s.y_bar;
  }
  return xyz / white_y;
}

namespace {

// IEC 61966-2-1's matrix from XYZ (D65) to linear sRGB.
Vec3 linear_srgb(const Vec3& xyz) {
  return Vec3(3.2406 * xyz.x() - 1.5372 * xyz.y() - 0.4986 * xyz.z(),
              -0.9689 * xyz.x() + 1.8758 * xyz.y() + 0.0415 * xyz.z(),
              0.0557 * xyz.x() - 0.2040 * xyz.y() + 1.0570 * xyz.z());
}

double srgb_transfer(double v) {
  v = std::clamp(v, 0.0, 1.0);
  return v <= 0.0031308 ? 12.92 * v : 1.055 * std::pow(v, 1.0 / 2.4) - 0.055;
}

Vec3 white_xyz() {
  return xyz_under_d65([](const SpectralSample&) { return 1.0; });
}

}  // namespace

Vec3 display_srgb(const Vec3& xyz) {
  // White balance: per-channel gains that take the perfect white to (1, 1, 1), as a camera's
  // balance does (they differ from 1 by under 0.1 %: the table's D65 and the matrix's agree).
  static const Vec3 white = linear_srgb(white_xyz());
  const Vec3 rgb = linear_srgb(xyz).cwiseQuotient(white);
  return Vec3(srgb_transfer(rgb.x()), srgb_transfer(rgb.y()), srgb_transfer(rgb.z()));
}

Vec3 cielab(const Vec3& xyz) {
  static const Vec3 white = white_xyz();
  auto f = [](double t) {
    constexpr double d = 6.0 / 29.0;
    return t > d * d * d ? std::cbrt(t) : t / (3.0 * d * d) + 4.0 / 29.0;
  };
  const double fx = f(xyz.x() / white.x()), fy = f(xyz.y() / white.y()), fz = f(xyz.z() / white.z());
  return Vec3(116.0 * fy - 16.0, 500.0 * (fx - fy), 200.0 * (fy - fz));
}

Vec3 tissue_xyz(const TissueOptics& t) {
  return xyz_under_d65([&](const SpectralSample& s) {
    return tissue_reflectance(absorption_per_mm(t, s), reduced_scattering_per_mm(t, s.nm));
  });
}

Vec3 tissue_srgb(const TissueOptics& t) { return display_srgb(tissue_xyz(t)); }

// The make-up of each tissue, from S. L. Jacques, "Optical properties of biological tissues: a
// review", Phys. Med. Biol. 58 (2013) R37:
// - scattering: Table 2's means, "fatty tissue" (a = 18.4 cm⁻¹, b = 0.672) for fat and "other soft
//   tissues" (a = 18.9 cm⁻¹, b = 1.286) for the rest. Table 1's fits for the liver alone (a = 9.0
//   and 16.5 cm⁻¹) lie below the mean: with them the liver would come out darker still;
// - adipose tissue: Table 3's only human abdominal row, in vivo (Jakubowski et al. 2004, J. Biomed.
//   Opt. 9:230): B = 0.54 %, S = 76 %, W = 11 %, F = 69 %; β-carotene 1472 nmol/kg, abdominal
//   adipose tissue by HPLC of biopsies (Chung et al. 2009, Am. J. Clin. Nutr. 90:533), taken as
//   1.47 µmol per litre (adipose tissue's density, about 0.9 kg/l, would lower it by a tenth). The
//   other carotenoids there (lycopene 3.3, lutein 0.46, α-carotene 0.28 µmol/kg, ibid.) have no
//   openly licensed spectrum here: fat's yellow is understated;
// - bowel and kidney: Table 3's optical measurements in vivo (Solonenko et al. 2002, Phys. Med.
//   Biol. 47:857, canine): bowel B = 5.11 %, S = 80 % (small bowel and colon), kidney
//   B = 14.61 %, S = 70 %;
// - muscle, pancreas, liver: no optical row, so Table 3's whole-organ blood volume fractions of
//   Weaver et al. 1989 (Comp. Biochem. Physiol. A 94:401, sheep and horse): 1.16 %, 12.9 %, 49.5 %.
//   They count the large vessels too, so they are upper bounds for the parenchyma a surface shows:
//   the liver's computed colour is darker than the liver in most laparoscopic images. S = 76 %, the
//   human in vivo abdominal value above. W = 75 % for every organ, lean tissue's water (its
//   absorption, under 0.003 mm⁻¹ from 380 to 780 nm, is under 1 % of the blood's: the colour does
//   not depend on it).
// Not modelled: bile (no openly licensed spectrum of its in vivo form; the liver's brown is weaker
// than in life), β-carotene's shift from hexane to fat (a few nm), and the packaging of blood in
// vessels (it lowers the effective absorption of large vessels, not of capillaries and sinusoids).
const TissueOptics& tissue_optics(Tissue t) {
  // {B, S, W, F, β-carotene µM, a cm⁻¹, b}
  static const TissueOptics adipose{0.0054, 0.76, 0.11, 0.69, 1.472, 18.4, 0.672};
  auto organ = [](double blood, double saturation) { return TissueOptics{blood, saturation, 0.75, 0.0, 0.0, 18.9, 1.286}; };
  static const TissueOptics muscle = organ(0.0116, 0.76), liver = organ(0.495, 0.76), bowel = organ(0.0511, 0.80),
                            pancreas = organ(0.129, 0.76), kidney = organ(0.1461, 0.70);
  switch (t) {
    case Tissue::Adipose: return adipose;
    case Tissue::Muscle: return muscle;
    case Tissue::Liver: return liver;
    case Tissue::Bowel: return bowel;
    case Tissue::Pancreas: return pancreas;
    case Tissue::Kidney: return kidney;
  }
  throw std::logic_error("tissue_optics: unknown tissue");
}

}  // namespace pneumo
