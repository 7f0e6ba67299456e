// libFuzzer target: what `pneumo serve` reads from a request as JSON (host/serve/request_json.h) on
// arbitrary bytes: a POST's body checked against each endpoint's keys, and the `port` query
// parameter read as a scene's port. Every input must give a value or an InputError.
#include <string>

#include "fuzz_support.h"
#include "scene/scene.h"
#include "serve/request_json.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace pneumo;
  fuzz::quiet();
  const std::string text(reinterpret_cast<const char*>(data), size);
  fuzz::expect_only_input_errors([&] {
    const nlohmann::json body = serve::read_json_object(text, "the body");
    serve::check_known_keys(body, "inflate", {"pressure_mmhg", "wall_young_kpa", "preset"});
  });
  return fuzz::expect_only_input_errors([&] {
    nlohmann::json port = serve::read_json_object(text, "port");
    port["name"] = "view";
    read_port(port, "the view's port");
  });
}
