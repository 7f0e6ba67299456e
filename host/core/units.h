#pragma once
// Unit conversions at the interface (mm, mmHg, kPa, ms) to SI inside the solver.
namespace pneumo::units {

constexpr double kPaPerMmHg = 133.322387415;  // 1 mmHg in pascal
constexpr double kMetresPerMm = 1e-3;
constexpr double kSecondsPerMs = 1e-3;
constexpr double kPaPerKPa = 1e3;

constexpr double mmhg_to_pa(double p_mmhg) { return p_mmhg * kPaPerMmHg; }
constexpr double mm_to_m(double x_mm) { return x_mm * kMetresPerMm; }
constexpr double m_to_mm(double x_m) { return x_m / kMetresPerMm; }
constexpr double ms_to_s(double t_ms) { return t_ms * kSecondsPerMs; }
constexpr double kpa_to_pa(double e_kpa) { return e_kpa * kPaPerKPa; }

}  // namespace pneumo::units
