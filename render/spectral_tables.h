#pragma once
// Spectral tables for the tissue colours (render/tissue_colour.h, docs/rendering.md "Tissue colours"):
// 380 to 780 nm every 5 nm, the interval and step CIE 015:2018 recommends for colorimetry.
// Provenance and licences of every column: data/spectra/README.md.
#include <array>

namespace pneumo {

struct SpectralSample {
  int nm;
  double x_bar, y_bar, z_bar;  // CIE 1931 2° colour-matching functions
  double d65;                  // CIE standard illuminant D65, relative spectral power (100 at 560 nm)
  double hbo2, hb;             // molar extinction of oxy- and deoxyhaemoglobin, decadic, mm⁻¹ per µM
  double water, fat;           // absorption coefficient of pure water and of pure fat, mm⁻¹
  double beta_carotene;        // molar extinction of β-carotene, decadic, mm⁻¹ per µM
};

inline constexpr int kSpectralSamples = 81;
extern const std::array<SpectralSample, kSpectralSamples> kSpectralTable;

}  // namespace pneumo
