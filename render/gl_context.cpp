#include "render/gl_context.h"

#include <dlfcn.h>

#define EGL_EGL_PROTOTYPES 0  // no linked EGL symbols: everything through dlopen (gl_api.h)
#include <EGL/egl.h>
#include <EGL/eglext.h>

#include <mutex>
#include <stdexcept>
#include <vector>

#include "core/error.h"
#include "core/log.h"
#include "render/gl_api.h"

namespace pneumo {
namespace {

// OSMesa's few entry points and constants (GL/osmesa.h), declared here so that its header, which
// pulls in the legacy GL/gl.h, does not meet glcorearb.h.
using OSMesaContext = struct osmesa_context*;
constexpr int kOsmesaFormat = 0x22, kOsmesaDepthBits = 0x30, kOsmesaProfile = 0x33, kOsmesaCoreProfile = 0x34,
              kOsmesaMajor = 0x36, kOsmesaMinor = 0x37;
using OsCreateAttribs = OSMesaContext (*)(const int*, OSMesaContext);
using OsMakeCurrent = unsigned char (*)(OSMesaContext, void*, unsigned, int, int);
using OsDestroy = void (*)(OSMesaContext);
using OsGetProc = void* (*)(const char*);

struct Egl {
  void* lib = nullptr;
  PFNEGLGETPROCADDRESSPROC GetProcAddress = nullptr;
  PFNEGLQUERYSTRINGPROC QueryString = nullptr;
  PFNEGLGETPLATFORMDISPLAYEXTPROC GetPlatformDisplayEXT = nullptr;
  PFNEGLQUERYDEVICESEXTPROC QueryDevicesEXT = nullptr;
  PFNEGLINITIALIZEPROC Initialize = nullptr;
  PFNEGLTERMINATEPROC Terminate = nullptr;
  PFNEGLCHOOSECONFIGPROC ChooseConfig = nullptr;
  PFNEGLBINDAPIPROC BindAPI = nullptr;
  PFNEGLCREATECONTEXTPROC CreateContext = nullptr;
  PFNEGLDESTROYCONTEXTPROC DestroyContext = nullptr;
  PFNEGLMAKECURRENTPROC MakeCurrent = nullptr;
  PFNEGLGETERRORPROC GetError = nullptr;
};

Egl* g_egl = nullptr;       // for the GL loader callback
OsGetProc g_os_getproc = nullptr;
void* g_libopengl = nullptr;

void* egl_get_proc(const char* name) {
  void* p = reinterpret_cast<void*>(g_egl->GetProcAddress(name));
  // EGL 1.5 returns core functions too; older drivers may not: then libOpenGL's export.
  if (!p && g_libopengl) p = dlsym(g_libopengl, name);
  return p;
}
void* osmesa_get_proc(const char* name) { return g_os_getproc(name); }

std::string hex(unsigned v) {
  char b[16];
  std::snprintf(b, sizeof b, "0x%04x", v);
  return b;
}

}  // namespace

struct GlContext::Impl {
  Egl egl;
  EGLDisplay display = EGL_NO_DISPLAY;
  EGLContext context = EGL_NO_CONTEXT;
  void* os_lib = nullptr;
  OSMesaContext os_ctx = nullptr;
  OsMakeCurrent os_make_current = nullptr;
  OsDestroy os_destroy = nullptr;
  std::vector<unsigned char> os_buffer;  // OSMesaMakeCurrent needs a client buffer (unused: FBO)

  void load_egl() {
    if (egl.lib) return;
    egl.lib = dlopen("libEGL.so.1", RTLD_NOW | RTLD_LOCAL);
    if (!egl.lib) throw std::runtime_error(std::string("cannot open libEGL.so.1: ") + dlerror());
    egl.GetProcAddress = reinterpret_cast<PFNEGLGETPROCADDRESSPROC>(dlsym(egl.lib, "eglGetProcAddress"));
    if (!egl.GetProcAddress) throw std::runtime_error("libEGL.so.1 has no eglGetProcAddress");
    auto get = [&](auto& fn, const char* name) {
      fn = reinterpret_cast<std::remove_reference_t<decltype(fn)>>(egl.GetProcAddress(name));
      if (!fn) fn = reinterpret_cast<std::remove_reference_t<decltype(fn)>>(dlsym(egl.lib, name));
    };
    get(egl.QueryString, "eglQueryString");
    get(egl.GetPlatformDisplayEXT, "eglGetPlatformDisplayEXT");
    get(egl.QueryDevicesEXT, "eglQueryDevicesEXT");
    get(egl.Initialize, "eglInitialize");
    get(egl.Terminate, "eglTerminate");
    get(egl.ChooseConfig, "eglChooseConfig");
    get(egl.BindAPI, "eglBindAPI");
    get(egl.CreateContext, "eglCreateContext");
    get(egl.DestroyContext, "eglDestroyContext");
    get(egl.MakeCurrent, "eglMakeCurrent");
    get(egl.GetError, "eglGetError");
    if (!egl.Initialize || !egl.ChooseConfig || !egl.CreateContext || !egl.MakeCurrent || !egl.BindAPI ||
        !egl.GetPlatformDisplayEXT)
      throw std::runtime_error("libEGL.so.1 lacks EGL 1.4 functions or eglGetPlatformDisplayEXT");
    g_libopengl = dlopen("libOpenGL.so.0", RTLD_NOW | RTLD_LOCAL);
  }

  // Initialises `dpy` and creates a core context on it; on failure terminates it and throws.
  void egl_context_on(EGLDisplay dpy) {
    EGLint major = 0, minor = 0;
    if (!dpy || !egl.Initialize(dpy, &major, &minor))
      throw std::runtime_error("eglInitialize failed (" + hex(egl.GetError()) + ")");
    // Without EGL_PBUFFER_BIT Mesa's surfaceless platform offers zero configs (platform.md).
    const EGLint config_attribs[] = {EGL_SURFACE_TYPE, EGL_PBUFFER_BIT, EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT,
                                     EGL_NONE};
    EGLConfig config = nullptr;
    EGLint n = 0;
    if (!egl.ChooseConfig(dpy, config_attribs, &config, 1, &n) || n < 1) config = nullptr;  // EGL_NO_CONFIG_KHR
    if (!egl.BindAPI(EGL_OPENGL_API)) {
      egl.Terminate(dpy);
      throw std::runtime_error("eglBindAPI(EGL_OPENGL_API) failed");
    }
    // Ask 4.5 core first (Mesa answers 4.5 to a 3.3 request anyway; 4.6 fails there), then 3.3.
    EGLContext ctx = EGL_NO_CONTEXT;
    for (int want_minor_major : {45, 33}) {
      const EGLint ctx_attribs[] = {EGL_CONTEXT_MAJOR_VERSION, want_minor_major / 10,
                                    EGL_CONTEXT_MINOR_VERSION, want_minor_major % 10,
                                    EGL_CONTEXT_OPENGL_PROFILE_MASK, EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT, EGL_NONE};
      ctx = egl.CreateContext(dpy, config, EGL_NO_CONTEXT, ctx_attribs);
      if (ctx != EGL_NO_CONTEXT) break;
    }
    if (ctx == EGL_NO_CONTEXT) {
      const std::string err = hex(egl.GetError());
      egl.Terminate(dpy);
      throw std::runtime_error("eglCreateContext (OpenGL 4.5/3.3 core) failed (" + err + ")");
    }
    if (!egl.MakeCurrent(dpy, EGL_NO_SURFACE, EGL_NO_SURFACE, ctx)) {
      const std::string err = hex(egl.GetError());
      egl.DestroyContext(dpy, ctx);
      egl.Terminate(dpy);
      throw std::runtime_error("eglMakeCurrent without a surface failed (" + err + ")");
    }
    display = dpy;
    context = ctx;
    g_egl = &egl;
    gl::load_api(egl_get_proc);
  }

  void create_egl_device() {
    load_egl();
    if (!egl.QueryDevicesEXT) throw std::runtime_error("EGL_EXT_device_enumeration is not available");
    EGLDeviceEXT devices[16];
    EGLint count = 0;
    if (!egl.QueryDevicesEXT(16, devices, &count) || count == 0) throw std::runtime_error("no EGL device found");
    std::string why;
    for (EGLint i = 0; i < count; ++i) {
      try {
        egl_context_on(egl.GetPlatformDisplayEXT(EGL_PLATFORM_DEVICE_EXT, devices[i], nullptr));
        return;
      } catch (const std::exception& e) {
        why += (why.empty() ? "" : "; ") + std::string("device ") + std::to_string(i) + ": " + e.what();
      }
    }
    throw std::runtime_error(why);
  }

  void create_egl_surfaceless() {
    load_egl();
    egl_context_on(egl.GetPlatformDisplayEXT(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr));
  }

  void create_osmesa() {
    os_lib = dlopen("libOSMesa.so.8", RTLD_NOW | RTLD_LOCAL);
    if (!os_lib) os_lib = dlopen("libOSMesa.so", RTLD_NOW | RTLD_LOCAL);
    if (!os_lib) throw std::runtime_error(std::string("cannot open libOSMesa.so.8: ") + dlerror());
    auto create = reinterpret_cast<OsCreateAttribs>(dlsym(os_lib, "OSMesaCreateContextAttribs"));
    os_make_current = reinterpret_cast<OsMakeCurrent>(dlsym(os_lib, "OSMesaMakeCurrent"));
    os_destroy = reinterpret_cast<OsDestroy>(dlsym(os_lib, "OSMesaDestroyContext"));
    g_os_getproc = reinterpret_cast<OsGetProc>(dlsym(os_lib, "OSMesaGetProcAddress"));
    if (!create || !os_make_current || !os_destroy || !g_os_getproc)
      throw std::runtime_error("libOSMesa lacks OSMesaCreateContextAttribs/MakeCurrent/GetProcAddress");
    for (int want : {45, 33}) {
      const int attribs[] = {kOsmesaFormat, GL_RGBA, kOsmesaDepthBits, 0, kOsmesaProfile, kOsmesaCoreProfile,
                             kOsmesaMajor, want / 10, kOsmesaMinor, want % 10, 0};
      os_ctx = create(attribs, nullptr);
      if (os_ctx) break;
    }
    if (!os_ctx) throw std::runtime_error("OSMesaCreateContextAttribs (OpenGL 4.5/3.3 core) failed");
    os_buffer.assign(16 * 16 * 4, 0);
    if (!os_make_current(os_ctx, os_buffer.data(), GL_UNSIGNED_BYTE, 16, 16))
      throw std::runtime_error("OSMesaMakeCurrent failed");
    gl::load_api(osmesa_get_proc);
  }

  void make_current() {
    if (context != EGL_NO_CONTEXT) {
      if (!egl.MakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, context))
        throw std::runtime_error("eglMakeCurrent failed (" + hex(egl.GetError()) + ")");
    } else if (os_ctx) {
      if (!os_make_current(os_ctx, os_buffer.data(), GL_UNSIGNED_BYTE, 16, 16))
        throw std::runtime_error("OSMesaMakeCurrent failed");
    }
  }

  void release_current() {
    if (context != EGL_NO_CONTEXT) egl.MakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
    // OSMesa binds a context per thread and lets another thread bind it: nothing to release.
  }

  ~Impl() {
    if (context != EGL_NO_CONTEXT) {
      egl.MakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
      egl.DestroyContext(display, context);
      egl.Terminate(display);
    }
    if (os_ctx) os_destroy(os_ctx);
    // The libraries stay loaded: drivers keep threads and atexit handlers that point into them.
  }
};

namespace {
constexpr GlBackend kGlBackends[] = {GlBackend::Auto, GlBackend::EglDevice, GlBackend::EglSurfaceless, GlBackend::OSMesa};
}  // namespace

std::string gl_backend_names() {
  std::string names;
  for (GlBackend b : kGlBackends) names += (names.empty() ? "" : ", ") + std::string(gl_backend_name(b));
  return names;
}

GlBackend parse_gl_backend(const std::string& name) {
  for (GlBackend b : kGlBackends)
    if (name == gl_backend_name(b)) return b;
  throw InputError("OpenGL back end '" + name + "' is not one of: " + gl_backend_names());
}

const char* gl_backend_name(GlBackend b) {
  switch (b) {
    case GlBackend::Auto: return "auto";
    case GlBackend::EglDevice: return "egl-device";
    case GlBackend::EglSurfaceless: return "egl-surfaceless";
    case GlBackend::OSMesa: return "osmesa";
  }
  return "?";
}

GlContext::GlContext(GlBackend backend) : impl_(std::make_unique<Impl>()) {
  std::vector<GlBackend> order;
  if (backend == GlBackend::Auto)
    order = {GlBackend::EglDevice, GlBackend::EglSurfaceless, GlBackend::OSMesa};
  else
    order = {backend};
  std::string why;
  for (GlBackend b : order) {
    try {
      if (b == GlBackend::EglDevice) impl_->create_egl_device();
      if (b == GlBackend::EglSurfaceless) impl_->create_egl_surfaceless();
      if (b == GlBackend::OSMesa) impl_->create_osmesa();
      info_.backend = b;
      break;
    } catch (const std::exception& e) {
      why += (why.empty() ? "" : "; ") + std::string(gl_backend_name(b)) + ": " + e.what();
      log::debug(std::string("OpenGL: ") + gl_backend_name(b) + " failed: " + e.what());
    }
  }
  if (info_.backend == GlBackend::Auto) throw std::runtime_error("no offscreen OpenGL context: " + why);

  const gl::Api& g = gl::api();
  auto str = [&](GLenum e) {
    const GLubyte* s = g.GetString(e);
    return s ? std::string(reinterpret_cast<const char*>(s)) : std::string("?");
  };
  info_.version = str(GL_VERSION);
  info_.renderer = str(GL_RENDERER);
  info_.vendor = str(GL_VENDOR);
  info_.glsl_version = str(GL_SHADING_LANGUAGE_VERSION);
  GLint major = 0, minor = 0;
  g.GetIntegerv(GL_MAJOR_VERSION, &major);
  g.GetIntegerv(GL_MINOR_VERSION, &minor);
  g.GetIntegerv(GL_MAX_3D_TEXTURE_SIZE, &info_.max_3d_texture_size);
  if (major * 10 + minor < 33)
    throw std::runtime_error("OpenGL " + info_.version + " is older than the 3.3 core the renderer needs");
  log::info(std::string("OpenGL: ") + gl_backend_name(info_.backend) + ", " + info_.version + ", renderer " +
            info_.renderer + " (" + info_.vendor + ")");
}

GlContext::~GlContext() = default;

void GlContext::make_current() { impl_->make_current(); }
void GlContext::release_current() { impl_->release_current(); }

GlContext& shared_gl_context(GlBackend backend) {
  static std::mutex m;
  // Never destroyed: tearing a driver down from a static destructor races its own atexit handlers.
  static GlContext* ctx = nullptr;
  std::lock_guard<std::mutex> lock(m);
  if (!ctx) {
    ctx = new GlContext(backend);
  } else if (backend != GlBackend::Auto && backend != ctx->info().backend) {
    throw InputError(std::string("this process already renders with OpenGL back end ") +
                     gl_backend_name(ctx->info().backend) + "; cannot switch to " + gl_backend_name(backend));
  }
  return *ctx;
}

}  // namespace pneumo
