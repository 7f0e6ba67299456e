#pragma once
// The GL ray caster: uploads a RenderVolume as 3-D textures (HU as 16-bit or float, labels as
// 16-bit integers, the occupancy grid), runs shaders/raycast.frag over a full-screen triangle into
// a framebuffer object (RGBA32F colour + R32F depth) and reads the image back.
#include <memory>
#include <string>

#include "render/camera_model.h"
#include "render/gl_context.h"
#include "render/render_settings.h"

namespace pneumo {

class GlRayCaster {
 public:
  /// Compiles the shaders in `context` (made current).
  explicit GlRayCaster(GlContext& context);
  ~GlRayCaster();
  GlRayCaster(const GlRayCaster&) = delete;
  GlRayCaster& operator=(const GlRayCaster&) = delete;

  /// Uploads the volume. HU go into a 16-bit texture (R16_SNORM, exact for integer HU) when they
  /// are integers within ±32767 and `force_float` is off, else a 32-bit float texture.
  /// InputError when a dimension exceeds the driver's GL_MAX_3D_TEXTURE_SIZE.
  void set_volume(const RenderVolume& volume, bool force_float = false);

  /// Renders one view (blocks until the image is read back).
  RenderImage render(const ViewCamera& camera, const RenderSettings& settings);

  /// "r16_snorm" or "r32f": how the HU were uploaded.
  const std::string& hu_format() const;

  struct Impl;

 private:
  std::unique_ptr<Impl> impl_;
};

}  // namespace pneumo
