#include "cli/scene_inputs_options.h"

#include <filesystem>

#include "core/error.h"
#include "scene/scene_json.h"

namespace pneumo::cli {

void add_scene_source_options(CLI::App* cmd, SceneSource& s) {
  cmd->add_option("scene", s.scene, "Scene .json (optional with --ct: every default)");
  cmd->add_option("--ct", s.ct, "The CT (NIfTI, MetaImage, NRRD or a DICOM folder): replaces the scene's inputs.ct");
  cmd->add_option("--labels", s.labels,
                  "Its label map, e.g. TotalSegmentator's (roles from the names it carries): replaces inputs.labels");
  cmd->add_option("--label-names", s.label_names, "A CSV naming the label map's ids: replaces inputs.label_names");
}

Scene load_scene_source(const SceneSource& s) {
  if (s.scene.empty() && s.ct.empty())
    throw InputError("give a scene file, or the CT with --ct (and its label map with --labels)");
  nlohmann::json j = s.scene.empty() ? nlohmann::json::object() : read_scene_json(s.scene);
  if (!j.is_object()) return parse_scene(j, s.scene);   // the parser names what is wrong
  const auto absolute = [](const std::string& p) { return std::filesystem::absolute(p).lexically_normal().string(); };
  if (!s.ct.empty()) {
    // A new CT is a new case: the scene's label map and names were for its own CT.
    j["inputs"] = nlohmann::json::object();
    j["inputs"]["ct"] = absolute(s.ct);
  }
  if (!s.labels.empty()) j["inputs"]["labels"] = absolute(s.labels);
  if (!s.label_names.empty()) j["inputs"]["label_names"] = absolute(s.label_names);
  return parse_scene(j, s.scene);
}

}  // namespace pneumo::cli
