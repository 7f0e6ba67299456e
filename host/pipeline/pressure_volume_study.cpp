#include "pipeline/pressure_volume_study.h"

#include <algorithm>
#include <cmath>

#include "core/error.h"

namespace pneumo {

std::vector<double> default_pressure_volume_pressures() { return {0, 5, 10, 12, 15, 20, 25, 30}; }

namespace {
double volume_at(const std::vector<PressurePoint>& c, double p) {
  for (const PressurePoint& q : c)
    if (q.pressure_mmhg == p) return q.cavity_volume_ml;
  throw InputError("validate pressure-volume: the pressures must include " + std::to_string(p) + " mmHg");
}
}  // namespace

PressureVolumeStudy pressure_volume_study(const Scene& scene, std::vector<double> pressures_mmhg) {
  for (const double p : pressures_mmhg)   // before the sort, which needs an order NaN does not have
    if (!std::isfinite(p)) throw InputError("validate pressure-volume: --pressures-mmhg: every pressure must be a finite number");
  std::sort(pressures_mmhg.begin(), pressures_mmhg.end());
  for (const double p : {5.0, 15.0, 30.0})
    if (!std::binary_search(pressures_mmhg.begin(), pressures_mmhg.end(), p))
      throw InputError("validate pressure-volume: the pressures must include 5, 15 and 30 mmHg");
  // The curve goes through the scene's own checks (each 0 or 0.1–100 mmHg), as a scene's curve would:
  // a negative pressure would otherwise "converge" to a negative cavity.
  nlohmann::json j = scene.echo();
  j["load"]["pressure_curve_mmhg"] = pressures_mmhg;
  j["load"]["pressure_mmhg"] = pressures_mmhg.back();
  Scene sc;
  try {
    sc = parse_scene(j, scene.path);
  } catch (const InputError& e) {
    throw InputError(std::string("validate pressure-volume: --pressures-mmhg: ") + e.what());
  }
  const Simulation sim = simulate_scene(sc);
  PressureVolumeStudy s;
  s.curve = sim.pressure_curve;
  s.all_converged = std::all_of(s.curve.begin(), s.curve.end(), [](const PressurePoint& p) { return p.converged; });
  const double v5 = volume_at(s.curve, 5), v15 = volume_at(s.curve, 15), v30 = volume_at(s.curve, 30);
  s.compliance_ml_per_mmhg = (v15 - v5) / 10.0;
  s.fraction_of_30_at_15 = v30 > 0 ? v15 / v30 : 0.0;
  for (const PressurePoint& p : s.curve)
    if (p.pressure_mmhg == 12.0) s.volume_at_12_ml = p.cavity_volume_ml;
  return s;
}

nlohmann::json to_json(const PressureVolumeStudy& s) {
  nlohmann::json curve = nlohmann::json::array();
  for (const PressurePoint& p : s.curve)
    curve.push_back({{"pressure_mmhg", p.pressure_mmhg},
                     {"cavity_volume_ml", p.cavity_volume_ml},
                     {"anterior_rise_mm", p.anterior_rise_mm},
                     {"converged", p.converged},
                     {"steps", p.steps}});
  return {{"curve", curve},
          {"compliance_ml_per_mmhg", s.compliance_ml_per_mmhg},
          {"fraction_of_30_at_15", s.fraction_of_30_at_15},
          {"volume_at_12_ml", s.volume_at_12_ml},
          {"all_converged", s.all_converged},
          {"reference_fraction_patients", 0.67},
          {"reference_fraction_linear_wall", 0.5}};
}

}  // namespace pneumo
