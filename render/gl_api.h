#pragma once
// The OpenGL functions the renderer calls, as pointers loaded at run time from the context's own
// library (EGL's eglGetProcAddress or OSMesaGetProcAddress).
//
// Why pointers and not linked symbols: one binary carries both back ends, and linking libOSMesa
// together with libOpenGL/libGL sends GL calls to the wrong library (platform.md: glGetString
// returns NULL, framebuffers are incomplete). Loading everything through the current context's
// loader avoids that and needs no generated loader. Only the ~45 functions used here are listed.
#include <GL/glcorearb.h>

#include <string>

namespace pneumo::gl {

// X(name, type) for every function the renderer uses.
#define PNEUMO_GL_FUNCTIONS(X)                                            \
  X(GetString, PFNGLGETSTRINGPROC)                                        \
  X(GetIntegerv, PFNGLGETINTEGERVPROC)                                    \
  X(GetError, PFNGLGETERRORPROC)                                          \
  X(Viewport, PFNGLVIEWPORTPROC)                                          \
  X(ClearColor, PFNGLCLEARCOLORPROC)                                      \
  X(Clear, PFNGLCLEARPROC)                                                \
  X(Finish, PFNGLFINISHPROC)                                              \
  X(ReadPixels, PFNGLREADPIXELSPROC)                                      \
  X(ReadBuffer, PFNGLREADBUFFERPROC)                                      \
  X(PixelStorei, PFNGLPIXELSTOREIPROC)                                    \
  X(GenTextures, PFNGLGENTEXTURESPROC)                                    \
  X(DeleteTextures, PFNGLDELETETEXTURESPROC)                              \
  X(BindTexture, PFNGLBINDTEXTUREPROC)                                    \
  X(ActiveTexture, PFNGLACTIVETEXTUREPROC)                                \
  X(TexImage2D, PFNGLTEXIMAGE2DPROC)                                      \
  X(TexImage3D, PFNGLTEXIMAGE3DPROC)                                      \
  X(TexSubImage3D, PFNGLTEXSUBIMAGE3DPROC)                                \
  X(GetTexImage, PFNGLGETTEXIMAGEPROC)                                    \
  X(TexParameteri, PFNGLTEXPARAMETERIPROC)                                \
  X(GenFramebuffers, PFNGLGENFRAMEBUFFERSPROC)                            \
  X(DeleteFramebuffers, PFNGLDELETEFRAMEBUFFERSPROC)                      \
  X(BindFramebuffer, PFNGLBINDFRAMEBUFFERPROC)                            \
  X(FramebufferTexture2D, PFNGLFRAMEBUFFERTEXTURE2DPROC)                  \
  X(CheckFramebufferStatus, PFNGLCHECKFRAMEBUFFERSTATUSPROC)              \
  X(DrawBuffers, PFNGLDRAWBUFFERSPROC)                                    \
  X(GenVertexArrays, PFNGLGENVERTEXARRAYSPROC)                            \
  X(DeleteVertexArrays, PFNGLDELETEVERTEXARRAYSPROC)                      \
  X(BindVertexArray, PFNGLBINDVERTEXARRAYPROC)                            \
  X(DrawArrays, PFNGLDRAWARRAYSPROC)                                      \
  X(CreateShader, PFNGLCREATESHADERPROC)                                  \
  X(ShaderSource, PFNGLSHADERSOURCEPROC)                                  \
  X(CompileShader, PFNGLCOMPILESHADERPROC)                                \
  X(GetShaderiv, PFNGLGETSHADERIVPROC)                                    \
  X(GetShaderInfoLog, PFNGLGETSHADERINFOLOGPROC)                          \
  X(DeleteShader, PFNGLDELETESHADERPROC)                                  \
  X(CreateProgram, PFNGLCREATEPROGRAMPROC)                                \
  X(AttachShader, PFNGLATTACHSHADERPROC)                                  \
  X(LinkProgram, PFNGLLINKPROGRAMPROC)                                    \
  X(GetProgramiv, PFNGLGETPROGRAMIVPROC)                                  \
  X(GetProgramInfoLog, PFNGLGETPROGRAMINFOLOGPROC)                        \
  X(DeleteProgram, PFNGLDELETEPROGRAMPROC)                                \
  X(UseProgram, PFNGLUSEPROGRAMPROC)                                      \
  X(GetUniformLocation, PFNGLGETUNIFORMLOCATIONPROC)                      \
  X(Uniform1i, PFNGLUNIFORM1IPROC)                                        \
  X(Uniform1f, PFNGLUNIFORM1FPROC)                                        \
  X(Uniform1ui, PFNGLUNIFORM1UIPROC)                                      \
  X(Uniform2f, PFNGLUNIFORM2FPROC)                                        \
  X(Uniform3f, PFNGLUNIFORM3FPROC)                                        \
  X(Uniform3i, PFNGLUNIFORM3IPROC)                                        \
  X(UniformMatrix3fv, PFNGLUNIFORMMATRIX3FVPROC)

struct Api {
#define PNEUMO_GL_MEMBER(name, type) type name = nullptr;
  PNEUMO_GL_FUNCTIONS(PNEUMO_GL_MEMBER)
#undef PNEUMO_GL_MEMBER
};

/// The functions of the current context (filled by GlContext when it is made current).
const Api& api();

/// Loads every function through `get_proc`; throws std::runtime_error naming the first one
/// missing. `get_proc` returns nullptr for an unknown name.
using GetProc = void* (*)(const char* name);
void load_api(GetProc get_proc);

/// Throws std::runtime_error "<where>: GL error 0x…" when glGetError reports one.
void check_error(const std::string& where);

}  // namespace pneumo::gl
