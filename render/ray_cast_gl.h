#pragma once
// The GL ray caster: uploads a RenderVolume as 3-D textures (HU as 16-bit or float, labels as
// 16-bit integers, premultiplied organ colours as RGBA8, the occupancy grid), runs shaders/raycast.frag over a full-screen triangle into
// a framebuffer object (RGBA32F colour + R32F depth) and reads the image back.
#include <memory>
#include <string>
#include <vector>

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

  /// Uploads the volume with its shading gradients (voxel_gradients(), computed here once per
  /// volume). When the HU are integers within ±32767 and `force_float` is off, HU and gradient
  /// share one RGBA16_SNORM texture (exact: a shaded sample is one fetch); else the HU go into a
  /// 32-bit float texture and the gradient into an RGBA16_SNORM one.
  /// InputError when a dimension exceeds the driver's GL_MAX_3D_TEXTURE_SIZE. The volume must outlive
  /// the renders: the organ colours per voxel are built from its labels at the first render that shows
  /// them (and again when the colours change).
  void set_volume(const RenderVolume& volume, bool force_float = false);

  /// Renders one view (blocks until the image is read back).
  RenderImage render(const ViewCamera& camera, const RenderSettings& settings);

  /// "rgba16_snorm" (HU with the gradient) or "r32f": how the HU were uploaded.
  const std::string& hu_format() const;

  /// The gradient texture read back (3 int16 per voxel, i fastest), for tests.
  std::vector<int16_t> read_gradient_texture();

  struct Impl;

 private:
  std::unique_ptr<Impl> impl_;
};

}  // namespace pneumo
