#pragma once
// The CPU reference of the ray caster: plain C++ (double precision, OpenMP over rows), no
// empty-space skipping, written from the model in render_settings.h and not from the shader, so
// that the GL-vs-CPU tests would see a bug in either. Slow by design; tests use small images.
#include "render/camera_model.h"
#include "render/render_settings.h"

namespace pneumo {

RenderImage render_reference(const RenderVolume& volume, const ViewCamera& camera, const RenderSettings& settings);

}  // namespace pneumo
