#pragma once
// An offscreen OpenGL 3.3+ core context without a display (method.md §8, platform.md).
//
// Back ends, tried in this order by Backend::Auto:
//   1. EGL device platform (EGL_EXT_platform_device): the way on NVIDIA; Mesa lists llvmpipe too;
//   2. EGL on Mesa's surfaceless platform (EGL_MESA_platform_surfaceless);
//   3. OSMesa (Mesa's off-screen library; removed from Mesa 25.1, hence last).
// The libraries are opened with dlopen, never linked, so that EGL and OSMesa can live in one
// binary (see gl_api.h); the renderer draws into its own framebuffer object, no window surface.
// One context per process is enough for pneumo: it is created on first use and kept.
#include <memory>
#include <string>

namespace pneumo {

enum class GlBackend { Auto, EglDevice, EglSurfaceless, OSMesa };

/// "auto" | "egl-device" | "egl-surfaceless" | "osmesa"; anything else is an InputError naming them.
GlBackend parse_gl_backend(const std::string& name);
const char* gl_backend_name(GlBackend b);
/// Every back end's name, in the order Auto tries them after itself: "auto, egl-device, …".
std::string gl_backend_names();

struct GlContextInfo {
  GlBackend backend = GlBackend::Auto;  // the one in use (never Auto)
  std::string version, renderer, vendor, glsl_version;
  int max_3d_texture_size = 0;
};

class GlContext {
 public:
  /// Creates the context and makes it current on this thread; logs back end, version and
  /// renderer. Throws std::runtime_error listing why each back end tried failed.
  explicit GlContext(GlBackend backend = GlBackend::Auto);
  ~GlContext();
  GlContext(const GlContext&) = delete;
  GlContext& operator=(const GlContext&) = delete;

  const GlContextInfo& info() const { return info_; }
  /// Makes this context current on the calling thread (again).
  void make_current();
  /// Releases it from the calling thread, so that another may make it current (EGL refuses a
  /// context still current on a thread, even one that has ended). A thread that rendered and is about
  /// to end calls this (`pneumo serve`'s worker).
  void release_current();

  struct Impl;

 private:
  std::unique_ptr<Impl> impl_;
  GlContextInfo info_;
};

/// The process's shared context, created on first call with `backend` (later calls must ask for
/// the same back end or Auto; another one is an InputError since a process keeps one context).
GlContext& shared_gl_context(GlBackend backend = GlBackend::Auto);

}  // namespace pneumo
