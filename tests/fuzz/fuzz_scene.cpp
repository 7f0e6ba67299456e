// libFuzzer target: the scene parser on arbitrary bytes as a scene file (JSON with comments,
// duplicate keys refused, the parameter table's types, ranges and rules). Every input must give a
// scene or an InputError, and a scene that parsed must read back from its own echo (scene.h's
// contract for scene_used.json): a failure there aborts.
#include <cstdio>
#include <cstdlib>

#include "fuzz_support.h"
#include "scene/scene.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace pneumo;
  fuzz::quiet();
  const std::string path = fuzz::write_input("scene.json", data, size);
  return fuzz::expect_only_input_errors([&] {
    const Scene scene = load_scene(path);
    const nlohmann::json echo = scene.echo();
    try {
      const Scene again = parse_scene(echo, path);
      if (again.echo() != echo) {
        std::fprintf(stderr, "the echo of a scene does not read back to the same scene\n");
        std::abort();
      }
    } catch (const std::exception& e) {
      std::fprintf(stderr, "the echo of a valid scene is refused: %s\n", e.what());
      std::abort();
    }
  });
}
