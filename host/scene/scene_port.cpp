#include "scene/param_table.h"
#include "scene/scene.h"

namespace pneumo {

nlohmann::json port_json(const Port& p) { return scene_detail::scene_port_table().write(p); }

Port read_port(const nlohmann::json& j, const std::string& what) {
  scene_detail::ReadContext ctx;
  ctx.file = what;
  ctx.root = &scene_detail::scene_port_table();
  const scene_detail::At at{&ctx, "port"};
  Port p;
  scene_detail::scene_port_table().read(p, j, at);
  scene_detail::check_port(p, at);
  return p;
}

}  // namespace pneumo
