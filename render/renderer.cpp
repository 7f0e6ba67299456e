#include "render/renderer.h"

#include <stdexcept>

#include "render/ray_cast_ref.h"

namespace pneumo {

Renderer::Renderer(bool cpu_reference, GlBackend backend) {
  if (!cpu_reference) gl_ = std::make_unique<GlRayCaster>(shared_gl_context(backend));
}

void Renderer::set_volume(const RenderVolume& v) {
  volume_ = &v;
  viewed_.reset();
  if (gl_) {
    gl_->set_volume(v);
  } else if (v.smoothing_mm > 0.0) {
    // The reference would filter on every frame: filter once here, and hand it the filtered copy.
    volume_as_viewed(v, viewed_);
    viewed_->smoothing_mm = 0.0;
    volume_ = &*viewed_;
  }
}

RenderImage Renderer::render_pass(const ViewCamera& camera, const RenderSettings& settings) {
  if (gl_) return gl_->render(camera, settings);
  if (!volume_) throw std::logic_error("Renderer::render before set_volume");
  return render_reference(*volume_, camera, settings);
}

RenderImage Renderer::render(const ViewCamera& camera, const RenderSettings& settings) {
  if (settings.antialias_samples <= 1) return render_pass(camera, settings);
  // Model step 7: the mean of N passes at antialias_offset(k), each jittered with its own seed.
  RenderImage sum;
  for (int k = 0; k < settings.antialias_samples; ++k) {
    RenderSettings s = settings;
    const auto o = antialias_offset(k);
    s.pixel_offset_x = settings.pixel_offset_x + o[0];
    s.pixel_offset_y = settings.pixel_offset_y + o[1];
    s.jitter = true;
    s.jitter_seed = settings.jitter_seed + uint32_t(k);
    s.antialias_samples = 1;
    RenderImage pass = render_pass(camera, s);
    if (k == 0) {
      sum = std::move(pass);
      continue;
    }
    for (std::size_t i = 0; i < sum.rgba.size(); ++i) sum.rgba[i] += pass.rgba[i];
  }
  const float inv = 1.0f / float(settings.antialias_samples);
  for (float& x : sum.rgba) x *= inv;
  return sum;
}

nlohmann::json Renderer::describe() const {
  if (!gl_) return {{"renderer", "cpu-reference"}};
  const GlContextInfo& i = shared_gl_context().info();
  return {{"renderer", "opengl"},      {"backend", gl_backend_name(i.backend)}, {"gl_version", i.version},
          {"gl_renderer", i.renderer}, {"gl_vendor", i.vendor},                 {"hu_texture", gl_->hu_format()}};
}

}  // namespace pneumo
