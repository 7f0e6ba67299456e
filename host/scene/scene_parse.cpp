// Scene files → Scene: reading the text (JSON with comments, duplicate keys refused, errors with
// line and column), then the parameter table, then the cross-key rules. `pneumo serve` reads its
// scene and its requests' JSON with the same reader (parse_json_text).
#include <algorithm>
#include <cstring>
#include <filesystem>
#include <set>
#include <sstream>
#include <vector>

#include "core/error.h"
#include "core/input_file.h"
#include "scene/param_table.h"
#include "scene/scene.h"
#include "scene/scene_json.h"
#include "scene/scene_presets.h"

namespace pneumo {
namespace {

using scene_detail::json;

// nlohmann keeps the last of two equal keys without a word; in a scene that hides a mistake
// (two "pressure_mmhg", one of them ignored). This parser callback refuses them, naming the key's
// path. It tracks where the parser is: one frame per open object or array.
class DuplicateKeyCheck {
 public:
  explicit DuplicateKeyCheck(std::string file) : file_(std::move(file)) {}

  bool operator()(int /*depth*/, json::parse_event_t event, json& parsed) {
    switch (event) {
      case json::parse_event_t::object_start: open(false); break;
      case json::parse_event_t::array_start: open(true); break;
      case json::parse_event_t::object_end:
      case json::parse_event_t::array_end: frames_.pop_back(); break;
      case json::parse_event_t::key: {
        Frame& f = frames_.back();
        f.key = parsed.get<std::string>();
        if (!f.keys.insert(f.key).second)
          throw InputError(file_ + ": " + child_path(f) + " is given twice; each key may appear once");
        break;
      }
      case json::parse_event_t::value:
        if (!frames_.empty() && frames_.back().array) ++frames_.back().index;
        break;
    }
    return true;
  }

 private:
  struct Frame {
    bool array = false;
    std::string path, key;
    long index = -1;
    std::set<std::string> keys;
  };

  // A value starts in the current frame: its path is the frame's path plus its key or index.
  std::string child_path(Frame& f) const {
    if (f.array) return f.path + "[" + std::to_string(f.index) + "]";
    return f.path.empty() ? f.key : f.path + "." + f.key;
  }

  void open(bool array) {
    Frame f;
    f.array = array;
    if (!frames_.empty()) {
      Frame& parent = frames_.back();
      if (parent.array) ++parent.index;
      f.path = child_path(parent);
    }
    frames_.push_back(std::move(f));
  }

  std::string file_;
  std::vector<Frame> frames_;
};

// "line L, column C" of a byte offset (1-based, as editors count).
std::string line_column(const std::string& text, std::size_t byte) {
  std::size_t line = 1, column = 1;
  for (std::size_t i = 0; i < byte && i < text.size(); ++i) {
    if (text[i] == '\n') {
      ++line;
      column = 1;
    } else {
      ++column;
    }
  }
  return "line " + std::to_string(line) + ", column " + std::to_string(column);
}

// nlohmann's message without its "[json.exception.parse_error.101] parse error at line 3,
// column 5: " preamble (we say where ourselves, counting the same way).
std::string parse_problem(const json::exception& e) {
  std::string what = e.what();
  const std::size_t bracket = what.find("] ");
  if (bracket != std::string::npos) what = what.substr(bracket + 2);
  const std::size_t colon = what.find(": ");
  if (what.compare(0, 11, "parse error") == 0 && colon != std::string::npos) what = what.substr(colon + 2);
  return what;
}

// Bounded work for bounded input. A scene is a few kB and nests at most seven levels (the scene,
// render, paths, a path, its keyframes, a keyframe, a 3-vector); the limits leave room for
// hand-written ones many times larger, and stop a hostile one (200,000 nested "[") before the
// parser spends minutes and gigabytes on it.
constexpr std::uintmax_t kMaxSceneBytes = 16u << 20;
constexpr int kMaxSceneNesting = 64;

/// The deepest nesting of [ and { outside strings and comments (what the parser would build).
void check_nesting(const std::string& text, const std::string& path) {
  int depth = 0;
  bool in_string = false;
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (in_string) {
      if (c == '\\') ++i;
      else if (c == '"') in_string = false;
      continue;
    }
    if (c == '"') in_string = true;
    else if (c == '/' && i + 1 < text.size() && text[i + 1] == '/') i = std::min(text.find('\n', i), text.size());
    else if (c == '/' && i + 1 < text.size() && text[i + 1] == '*') {
      const std::size_t end = text.find("*/", i + 2);
      i = end == std::string::npos ? text.size() : end + 1;   // an open comment: the parser reports it
    } else if (c == '[' || c == '{') {
      if (++depth > kMaxSceneNesting)
        throw file_error(path, "nests arrays and objects deeper than " + std::to_string(kMaxSceneNesting) +
                                   " levels (at " + line_column(text, i) + "); a scene needs fewer than ten");
    } else if (c == ']' || c == '}') --depth;
  }
}

}  // namespace

json parse_json_text(const std::string& text, const std::string& origin) {
  check_nesting(text, origin);
  try {
    // Comments (// and /* */) are allowed: scenes are written by hand.
    return json::parse(text, DuplicateKeyCheck(origin), /*allow_exceptions=*/true, /*ignore_comments=*/true);
  } catch (const json::parse_error& e) {
    // e.byte is one past the offending character.
    throw file_error(origin, "invalid JSON at " + line_column(text, e.byte > 0 ? e.byte - 1 : 0) + ": " +
                                 parse_problem(e));
  } catch (const json::out_of_range& e) {
    // A number too large for a double (1e999): nlohmann reports it as out_of_range, with no position.
    throw file_error(origin, "invalid JSON: " + parse_problem(e));
  }
}

json read_scene_json(const std::string& path) {
  // The cap holds however the file is given: a FIFO or a device (a link to /dev/zero) has no size
  // to compare, and is refused before it is read (core/input_file.h).
  return parse_json_text(read_input_file(path, kMaxSceneBytes, "the scene file", "16 MB; scenes are a few kB"), path);
}

namespace {

/// The material model a scene's JSON names, else the default's (a misspelt one is left to the table, which
/// names the allowed values).
MaterialModel named_material_model(const nlohmann::json& scene) {
  const MaterialModel fallback = SceneMaterial{}.model;
  if (!scene.is_object()) return fallback;
  const auto m = scene.find("material");
  if (m == scene.end() || !m->is_object()) return fallback;
  const auto name = m->find("model");
  if (name == m->end() || !name->is_string()) return fallback;
  return enum_from_name<MaterialModel>(name->get<std::string>()).value_or(fallback);
}

/// Adds the keys of `defaults` that `scene` lacks, object by object. Not RFC 7386's merge patch of the scene over
/// the defaults: that would drop the scene's nulls, and null is how a scene switches a default off.
void fill_absent(nlohmann::json& scene, const nlohmann::json& defaults) {
  if (!scene.is_object()) return;   // the table names the wrong type
  for (const auto& [key, value] : defaults.items()) {
    const auto it = scene.find(key);
    if (it == scene.end()) scene[key] = value;
    else if (it->is_object() && value.is_object()) fill_absent(*it, value);
  }
}

/// The defaults a model changes: the co-rotational law is linear and has no stiffening, so the default's b
/// (Demiray's) becomes 0 for it; a stiffening the scene gives is refused by validate_scene. Nor does it
/// get the default's fat at 3 kPa: 12 mmHg (1.6 kPa) strains such tissue past 50 %, where a linear law
/// lets a tetrahedron turn inside out at lower energy and Newton finds no step that keeps them all
/// (on the real CT: "no descent"); its fat takes the wall's E unless the scene gives fat_young_kpa.
nlohmann::json model_patch(MaterialModel model) {
  if (model == MaterialModel::FemCorotational)
    return {{"material", {{"stiffening", 0.0}, {"fat_young_kpa", nullptr}}}};
  return nlohmann::json::object();
}

}  // namespace

Scene parse_scene(const nlohmann::json& j, const std::string& origin_path) {
  namespace fs = std::filesystem;
  scene_detail::ReadContext ctx;
  ctx.file = origin_path.empty() ? "scene" : origin_path;
  ctx.folder = (origin_path.empty() ? fs::current_path() : fs::absolute(origin_path).parent_path())
                   .lexically_normal()
                   .string();
  ctx.root = &scene_detail::scene_table();

  Scene s;
  // A preset supplies values for the keys the scene does not give itself (merge_patch: the scene's keys win).
  // A misspelt preset is left to the table, which names the allowed values.
  // Defaults that depend on the material model the scene names (or the default's) fill the keys the scene does
  // not give: the preset's, whose solver follows the model, and the model's own.
  const MaterialModel model = named_material_model(j);
  nlohmann::json merged = j;
  if (const std::optional<ScenePreset> p = find_preset(j); p && *p != ScenePreset::None)
    fill_absent(merged, preset_patch(*p, model));
  fill_absent(merged, model_patch(model));
  scene_detail::scene_table().read(s, merged, scene_detail::At{&ctx, ""});
  scene_detail::assign_roles_by_name(s, merged);
  scene_detail::validate_scene(s, ctx);
  s.path = origin_path;
  s.folder = ctx.folder;
  return s;
}

Scene load_scene(const std::string& path) { return parse_scene(read_scene_json(path), path); }

Scene default_scene() { return Scene{}; }

nlohmann::json Scene::echo() const {
  nlohmann::json j = scene_detail::scene_table().write(*this);
  // The ids the label names gave (roles.ids_from_names) are not the scene's own: the echo leaves them
  // out of the role lists and a run of it derives them again, so a key that changes what the names
  // decide (roles.compliant_lungs, by_name) takes effect instead of being overridden by lists it wrote.
  if (!roles.ids_from_names.empty())
    for (const char* key : {"wall_labels", "viscera_labels", "fixed_labels"}) {
      nlohmann::json& list = j["roles"][key];
      nlohmann::json kept = nlohmann::json::array();
      for (const auto& id : list)
        if (!std::binary_search(roles.ids_from_names.begin(), roles.ids_from_names.end(), id.get<int>()))
          kept.push_back(id);
      list = kept;
    }
  return j;
}

}  // namespace pneumo
