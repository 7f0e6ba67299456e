#pragma once
// The JSON `pneumo serve` takes from a request (a POST's body, the `port` query parameter): read
// with the scene files' reader (parse_json_text: a key given twice, anything after the value, or
// nesting beyond its limit refused), and each object's keys checked against those its endpoint
// reads, so that a misspelt key is refused by name instead of being ignored.
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace pneumo::serve {

/// `text` as a JSON object ("" reads as {}); InputError naming `what` and the problem otherwise.
nlohmann::json read_json_object(const std::string& text, const std::string& what);

/// Refuses a key of `object` not among `known`: InputError `<what>: "<key>" is an unknown key; did
/// you mean "<near>"?`, or the known keys listed when none is near.
void check_known_keys(const nlohmann::json& object, const std::string& what, const std::vector<std::string>& known);

}  // namespace pneumo::serve
