#include "serve/request_json.h"

#include "core/error.h"
#include "scene/scene_json.h"

namespace pneumo::serve {

nlohmann::json read_json_object(const std::string& text, const std::string& what) {
  nlohmann::json j = parse_json_text(text.empty() ? "{}" : text, what);
  if (!j.is_object()) throw InputError(what + " must be a JSON object");
  return j;
}

void check_known_keys(const nlohmann::json& object, const std::string& what, const std::vector<std::string>& known) {
  for (const auto& item : object.items()) {
    const std::string& key = item.key();
    bool is_known = false;
    for (const std::string& k : known) is_known |= k == key;
    if (is_known) continue;
    const std::string near = nearest_known_name(key, known);
    std::string hint;
    if (!near.empty()) {
      hint = "did you mean \"" + near + "\"?";
    } else {
      for (const std::string& k : known) hint += (hint.empty() ? "known keys: \"" : ", \"") + k + "\"";
    }
    throw InputError(what + ": \"" + key + "\" is an unknown key; " + hint);
  }
}

}  // namespace pneumo::serve
