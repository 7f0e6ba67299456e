#pragma once
// The render stage's one entry, as solve_on_device and warp_on_device are the others': the GL ray
// caster (ray_cast_gl.h) on an EGL or OSMesa context, or the CPU reference (ray_cast_ref.h), chosen
// here. Both implement render_settings.h's model and are held to each other by
// tests/test_render_gl_vs_ref.cpp.
#include <memory>
#include <optional>

#include <nlohmann/json.hpp>

#include "render/camera_model.h"
#include "render/gl_context.h"
#include "render/ray_cast_gl.h"
#include "render/render_settings.h"
#include "render/render_volume.h"

namespace pneumo {

class Renderer {
 public:
  /// The CPU reference when `cpu_reference`, else OpenGL on `backend` (throws when no context opens).
  Renderer(bool cpu_reference, GlBackend backend);
  /// The volume every later render() draws; it must outlive them (the GL path uploads it once).
  void set_volume(const RenderVolume& v);
  /// One view; with settings.antialias_samples > 1 the mean of that many passes (render_settings.h,
  /// model step 7).
  RenderImage render(const ViewCamera& camera, const RenderSettings& settings);
  /// What rendered: {"renderer": "cpu-reference"} or the GL back end, version, renderer, vendor.
  nlohmann::json describe() const;

 private:
  RenderImage render_pass(const ViewCamera& camera, const RenderSettings& settings);
  std::unique_ptr<GlRayCaster> gl_;   // null: the CPU reference
  const RenderVolume* volume_ = nullptr;
  std::optional<RenderVolume> viewed_;   // the reference path's filtered copy (smoothing_mm > 0)
};

}  // namespace pneumo
