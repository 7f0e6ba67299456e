#pragma once
// Unit conversions at the interface (mm, mmHg, kPa, ms) to SI inside the solver.
namespace pneumo::units {

constexpr double kPaPerMmHg = 133.322387415;  // 1 mmHg in pascal
constexpr double kMetresPerMm = 1e-3;
constexpr double kSecondsPerMs = 1e-3;
constexpr double kPaPerKPa = 1e3;
constexpr double kPaPerCmH2O = 98.0665;       // 1 cmH2O in pascal (ρ g h, 10 mm of water)
constexpr double kCubicMetresPerLitre = 1e-3;

constexpr double mmhg_to_pa(double p_mmhg) { return p_mmhg * kPaPerMmHg; }
constexpr double mm_to_m(double x_mm) { return x_mm * kMetresPerMm; }
constexpr double m_to_mm(double x_m) { return x_m / kMetresPerMm; }
constexpr double ms_to_s(double t_ms) { return t_ms * kSecondsPerMs; }
constexpr double kpa_to_pa(double e_kpa) { return e_kpa * kPaPerKPa; }
constexpr double cmh2o_to_pa(double p_cmh2o) { return p_cmh2o * kPaPerCmH2O; }
/// A compliance in the ventilator's unit, L/cmH2O, in m³/Pa.
constexpr double l_per_cmh2o_to_m3_per_pa(double c) { return c * kCubicMetresPerLitre / kPaPerCmH2O; }

}  // namespace pneumo::units
