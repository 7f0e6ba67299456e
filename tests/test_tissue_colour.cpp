// The tissue colours (render/tissue_colour.h, render/tissue_reflectance.h) against truths outside
// the code: the CIE's own chromaticities of its white points, the sRGB standard's transfer curve,
// Chandrasekhar's exact albedo of an isotropically scattering half-space, and energy conservation.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "render/tissue_colour.h"
#include "render/tissue_reflectance.h"
#include "render/transfer_function.h"

namespace pneumo {
namespace {

Vec3 chromaticity(const Vec3& xyz) { return xyz / xyz.sum(); }

// x̄, ȳ and z̄ enclose equal areas (CIE 015:2018 §3.1), so the equal-energy spectrum sits at (1/3, 1/3).
// The table is every fifth row of the CIE's 1 nm table: 1e-5 allows the coarser sum.
TEST(TissueColour, EqualEnergyWhiteIsAtOneThird) {
  Vec3 xyz = Vec3::Zero();
  for (const SpectralSample& s : kSpectralTable) xyz += Vec3(s.x_bar, s.y_bar, s.z_bar);
  const Vec3 c = chromaticity(xyz);
  EXPECT_NEAR(c.x(), 1.0 / 3.0, 1e-5);
  EXPECT_NEAR(c.y(), 1.0 / 3.0, 1e-5);
}

// D65's white point as CIE 015:2018 Table 3 gives it for the 2° observer: (0.31272, 0.32903).
TEST(TissueColour, D65WhiteIsTheCiesWhitePoint) {
  const Vec3 c = chromaticity(xyz_under_d65([](const SpectralSample&) { return 1.0; }));
  EXPECT_NEAR(c.x(), 0.31272, 5e-5);
  EXPECT_NEAR(c.y(), 0.32903, 5e-5);
}

// A spectrally flat grey stays grey through the matrix and the white balance, and is encoded by
// IEC 61966-2-1's curve: 1.055 · 0.18^(1/2.4) − 0.055 = 0.46135 for 18 % grey.
TEST(TissueColour, GreyIsEncodedByTheSrgbCurve) {
  const Vec3 rgb = display_srgb(xyz_under_d65([](const SpectralSample&) { return 0.18; }));
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(rgb[c], 1.055 * std::pow(0.18, 1.0 / 2.4) - 0.055, 1e-9) << c;
  const Vec3 lab = cielab(xyz_under_d65([](const SpectralSample&) { return 0.18; }));
  EXPECT_NEAR(lab.x(), 116.0 * std::cbrt(0.18) - 16.0, 1e-9);  // L* of 18 % grey, 49.5
  EXPECT_NEAR(lab.y(), 0.0, 1e-9);
  EXPECT_NEAR(lab.z(), 0.0, 1e-9);
}

// Chandrasekhar's H-function for isotropic scattering of single-scattering albedo ω (Radiative
// Transfer, 1950, Ch. V): H(μ) = 1 / (1 − (ω/2) μ ∫₀¹ H(μ′) / (μ + μ′) dμ′), solved by iteration
// (midpoint rule, 400 nodes). The plane albedo of a half-space lit at normal incidence, index
// matched, is 1 − H(1)·√(1 − ω).
double chandrasekhar_plane_albedo(double omega) {
  const int n = 400;
  std::vector<double> mu(n), h(n, 1.0);
  for (int i = 0; i < n; ++i) mu[i] = (i + 0.5) / n;
  auto integral = [&](double m) {
    double s = 0.0;
    for (int j = 0; j < n; ++j) s += h[j] / (m + mu[j]);
    return s / n;
  };
  for (int it = 0; it < 400; ++it) {
    std::vector<double> next(n);
    for (int i = 0; i < n; ++i) next[i] = 1.0 / (1.0 - 0.5 * omega * mu[i] * integral(mu[i]));
    h = next;
  }
  const double h1 = 1.0 / (1.0 - 0.5 * omega * integral(1.0));
  return 1.0 - h1 * std::sqrt(1.0 - omega);
}

// The Monte Carlo reference solves the transport equation: with g = 0 and n = 1 it must give the
// exact albedo, to within its statistics (4 standard errors) and the H-function's quadrature (1e-3).
TEST(TissueReflectance, MonteCarloIsChandrasekharsExactAlbedo) {
  for (double omega : {0.5, 0.9, 0.99}) {
    const ReflectanceEstimate mc = monte_carlo_reflectance(omega, 0.0, 1.0, 20000, 7);
    const double exact = chandrasekhar_plane_albedo(omega);
    EXPECT_NEAR(mc.reflectance, exact, 4.0 * mc.standard_error + 1e-3) << "omega " << omega;
  }
}

// Without absorption every photon comes back out: energy conservation, exact for a half-space.
TEST(TissueReflectance, NothingAbsorbedEverythingReturns) {
  EXPECT_EQ(kReflectanceTable[0], 1.0);
  EXPECT_EQ(tissue_reflectance(0.0, 1.0), 1.0);
  for (int k = 1; k < kReflectanceTableSize; ++k) EXPECT_LE(kReflectanceTable[k], kReflectanceTable[k - 1]) << k;
  EXPECT_LT(kReflectanceTable[kReflectanceTableSize - 1], 1e-3);  // a′ = 0: nothing scatters back
}

// The table is the Monte Carlo at tissue's g and n: entries drawn afresh with other seeds agree
// within 4 standard errors of both estimates.
TEST(TissueReflectance, TableIsTheMonteCarloAtTissuesAnisotropy) {
  for (int k : {8, 16, 24, 31}) {
    const double s = k * std::sqrt(3.0) / (kReflectanceTableSize - 1), albedo = 1.0 - s * s / 3.0;
    const ReflectanceEstimate mc = monte_carlo_reflectance(albedo, kTissueAnisotropy, kTissueRefractiveIndex, 20000, 99 + k);
    const double tolerance = 4.0 * std::hypot(mc.standard_error, kReflectanceTableError[k]);
    EXPECT_NEAR(kReflectanceTable[k], mc.reflectance, tolerance) << "k " << k << " albedo " << albedo;
  }
}

// Diffusion theory's total diffuse reflectance of a half-space with an index-mismatched boundary
// (Farrell, Patterson & Wilson 1992, Med. Phys. 19:879; A from Groenhuis et al. 1983).
double diffusion_reflectance(double albedo, double n) {
  const double r = -1.4399 / (n * n) + 0.7099 / n + 0.6681 + 0.0636 * n;
  const double A = (1.0 + r) / (1.0 - r);
  const double s = std::sqrt(3.0 * (1.0 - albedo));
  return 0.5 * albedo * (1.0 + std::exp(-4.0 / 3.0 * A * s)) * std::exp(-s);
}

// Diffusion theory is the transport equation's limit as absorption vanishes:
// within 2 % of the table for a′ ≥ 0.98, and far above it where blood absorbs (a′ = 0.5, the green
// of liver), which is why the colours take the table.
TEST(TissueReflectance, DiffusionTheoryHoldsOnlyWhereAbsorptionIsWeak) {
  for (int k = 1; k <= 4; ++k) {
    const double s = k * std::sqrt(3.0) / (kReflectanceTableSize - 1), albedo = 1.0 - s * s / 3.0;
    EXPECT_NEAR(diffusion_reflectance(albedo, kTissueRefractiveIndex) / kReflectanceTable[k], 1.0, 0.02) << k;
  }
  const double half = tissue_reflectance(1.0, 1.0);  // a′ = 0.5
  EXPECT_GT(diffusion_reflectance(0.5, kTissueRefractiveIndex), 1.5 * half);
}

// β-carotene's column: its absorption maximum in hexane lies at 450 ± 5 nm, where its specific
// absorbance A(1 %, 1 cm) = 2592 (Britton 1995, Carotenoids 1B) gives ε = 2592 · 536.9 / 10 =
// 139 160 cm⁻¹/M = 0.01392 mm⁻¹/µM; 3 % allows the 5 nm average over the peak. Nothing above 530 nm.
TEST(TissueColour, BetaCaroteneAbsorbsWhereAndAsMuchAsItsStandard) {
  const SpectralSample* peak = &kSpectralTable[0];
  for (const SpectralSample& s : kSpectralTable) {
    if (s.beta_carotene > peak->beta_carotene) peak = &s;
    if (s.nm > 530) {
      EXPECT_EQ(s.beta_carotene, 0.0) << s.nm;
    }
  }
  EXPECT_NEAR(peak->nm, 450, 5);
  EXPECT_NEAR(peak->beta_carotene, 2592.0 * 536.87 / 10.0 * 1e-7, 0.03 * 0.01392);
}

// A yellow pigment absorbs blue: with β-carotene, fat's b* rises, its lightness hardly moves.
TEST(TissueColour, BetaCaroteneTurnsFatYellow) {
  TissueOptics fat = tissue_optics(Tissue::Adipose);
  fat.beta_carotene_um = 0.0;
  const Vec3 without = cielab(tissue_xyz(fat));
  fat.beta_carotene_um = 6.0;
  const Vec3 with = cielab(tissue_xyz(fat));
  EXPECT_GT(with.z(), without.z() + 5.0);
  EXPECT_NEAR(with.x(), without.x(), 2.0);
}

// More blood, darker: at fixed scattering L* falls with B, and the colour stays a red-yellow one
// (a* and b* positive), as haemoglobin absorbs blue and green and passes red.
TEST(TissueColour, MoreBloodIsDarker) {
  TissueOptics t = tissue_optics(Tissue::Muscle);
  double last_l = 100.0;
  for (double b : {0.01, 0.05, 0.1, 0.3, 0.5}) {
    t.blood = b;
    const Vec3 lab = cielab(tissue_xyz(t));
    EXPECT_LT(lab.x(), last_l) << b;
    EXPECT_GT(lab.y(), 0.0) << b;
    EXPECT_GT(lab.z(), 0.0) << b;
    last_l = lab.x();
  }
}

// The laparoscopic preset's colours are the computed ones, at the HU and label ids it names; the
// other presets keep the identifying organ colours.
TEST(TissueColour, LaparoscopicPresetTakesTheComputedColours) {
  const TransferFunction tf = preset_transfer_function(RenderPreset::Laparoscopic);
  const std::pair<double, Tissue> points[] = {{-100, Tissue::Adipose}, {40, Tissue::Muscle}, {65, Tissue::Liver}};
  for (const auto& [hu, tissue] : points) {
    const Vec3 want = tissue_srgb(tissue_optics(tissue));
    EXPECT_LT((tf.colour_at(hu) - want).norm(), 1e-12) << hu;
  }
  const LabelColours lap = preset_label_colours(RenderPreset::Laparoscopic);
  const Vec3 liver = 255.0 * tissue_srgb(tissue_optics(Tissue::Liver));
  for (int c = 0; c < 3; ++c) EXPECT_EQ(int(lap.rgba[5][c]), int(std::lround(liver[c])));
  const LabelColours slicer = preset_label_colours(RenderPreset::CtSoftTissue);
  EXPECT_EQ(slicer.rgba[5], default_label_colours().rgba[5]);
  EXPECT_EQ(lap.rgba[52], default_label_colours().rgba[52]);  // the aorta: no published make-up here
}

}  // namespace
}  // namespace pneumo
