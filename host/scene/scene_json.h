#pragma once
// The one JSON reader of scene files, which `pneumo serve` reads its scene and its requests' JSON
// with too, and the scene's "did you mean" for a name it does not know.
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace pneumo {

/// JSON text read as a scene file's is: comments (// and /* */) allowed; a key given twice, anything
/// after the value, or nesting deeper than 64 levels refused. InputError "<origin>: <problem>", with
/// the line and column of a syntax error.
nlohmann::json parse_json_text(const std::string& text, const std::string& origin);

/// A scene file's JSON, before its keys are read: what load_scene parses (its size limit, then
/// parse_json_text), for a caller that keeps the JSON itself.
nlohmann::json read_scene_json(const std::string& path);

/// The name among `known` that `typed` most likely meant, as a scene's unknown key or value gets it
/// suggested (a near spelling, or the name with a unit or qualifier added or left off); "" when
/// none is near.
std::string nearest_known_name(const std::string& typed, const std::vector<std::string>& known);

}  // namespace pneumo
