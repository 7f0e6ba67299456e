#pragma once
// `pneumo validate pressure-volume`: the scene's cavity volume against pressure (each pressure from
// the last equilibrium), with what patients' curves are judged by: the compliance ΔV/ΔP in the
// clinical range and the share of the 30 mmHg volume reached by 15 mmHg (McDougall 1994: about 67 %
// of the delivered CO2 in patients, 94 % of the abdominal volume in pigs; a linear wall gives 50 %).
#include <vector>

#include <nlohmann/json.hpp>

#include "pipeline/simulate.h"
#include "scene/scene.h"

namespace pneumo {

struct PressureVolumeStudy {
  std::vector<PressurePoint> curve;      // 0 … 30 mmHg
  double compliance_ml_per_mmhg = 0;     // (V(15) − V(5)) / 10 mmHg: the clinical range
  double fraction_of_30_at_15 = 0;       // V(15) / V(30)
  double volume_at_12_ml = 0;
  bool all_converged = false;
};

/// The default pressures: 0, 5, 10, 12, 15, 20, 25, 30 mmHg.
std::vector<double> default_pressure_volume_pressures();
/// Solves `scene` at each pressure in `pressures_mmhg` (must hold 5, 15 and 30).
PressureVolumeStudy pressure_volume_study(const Scene& scene, std::vector<double> pressures_mmhg);
nlohmann::json to_json(const PressureVolumeStudy& s);

}  // namespace pneumo
