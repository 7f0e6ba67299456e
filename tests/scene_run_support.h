#pragma once
// `pneumo run` on a scene written in a scratch folder, as a user would run it: its exit, its
// messages and its metrics.json, for the tests that judge whole runs (any-CT cases, the diaphragm,
// every material model on the real CT).
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "cli_test_support.h"

namespace pneumo::testing_support {

struct SceneRun {
  int code = -1;
  std::string err;        // stderr
  std::string out;        // the output folder
  nlohmann::json metrics; // metrics.json; null when the run failed
};

/// Writes `scene` as dir/NAME.json and runs `pneumo -q run` on it into dir/NAME.
inline SceneRun run_scene(const ScratchDir& dir, const std::string& name, const nlohmann::json& scene) {
  const std::string path = dir.file(name + ".json");
  std::ofstream(path) << scene.dump(2);
  SceneRun s;
  s.out = dir.file(name);
  const CliResult r = run_pneumo("-q run " + path + " --out " + s.out);
  s.code = r.code;
  s.err = r.err;
  if (r.code == 0) s.metrics = nlohmann::json::parse(slurp(s.out + "/metrics.json"));
  return s;
}

}  // namespace pneumo::testing_support
