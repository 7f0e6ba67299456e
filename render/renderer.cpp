#include "render/renderer.h"

#include <stdexcept>

#include "render/ray_cast_ref.h"

namespace pneumo {

Renderer::Renderer(bool cpu_reference, GlBackend backend) {
  if (!cpu_reference) gl_ = std::make_unique<GlRayCaster>(shared_gl_context(backend));
}

void Renderer::set_volume(const RenderVolume& v) {
  volume_ = &v;
  if (gl_) gl_->set_volume(v);
}

RenderImage Renderer::render(const ViewCamera& camera, const RenderSettings& settings) {
  if (gl_) return gl_->render(camera, settings);
  if (!volume_) throw std::logic_error("Renderer::render before set_volume");
  return render_reference(*volume_, camera, settings);
}

nlohmann::json Renderer::describe() const {
  if (!gl_) return {{"renderer", "cpu-reference"}};
  const GlContextInfo& i = shared_gl_context().info();
  return {{"renderer", "opengl"},      {"backend", gl_backend_name(i.backend)}, {"gl_version", i.version},
          {"gl_renderer", i.renderer}, {"gl_vendor", i.vendor},                 {"hu_texture", gl_->hu_format()}};
}

}  // namespace pneumo
