#include "render/shader_program.h"

#include <stdexcept>

#include "render/embedded_shaders.h"

namespace pneumo::gl {
namespace {

std::string with_defines(const std::string& src, const std::vector<std::string>& defines) {
  if (defines.empty()) return src;
  std::string extra;
  for (const auto& d : defines) extra += "#define " + d + "\n";
  const std::size_t v = src.find("#version");
  const std::size_t eol = v == std::string::npos ? std::string::npos : src.find('\n', v);
  if (eol == std::string::npos) return extra + src;
  return src.substr(0, eol + 1) + extra + src.substr(eol + 1);
}

/// The info log of a shader or program, through its getters (glGetShaderiv/InfoLog or glGetProgramiv/InfoLog).
template <class GetIv, class GetLog>
std::string info_log(GLuint object, GetIv get_iv, GetLog get_log) {
  GLint len = 0;
  get_iv(object, GL_INFO_LOG_LENGTH, &len);
  std::string log(std::max(len, 1), '\0');
  get_log(object, len, nullptr, log.data());
  return log;
}

GLuint compile(GLenum type, const std::string& path, const std::vector<std::string>& defines) {
  const Api& g = api();
  const std::string src = with_defines(shader_source(path), defines);
  const GLuint s = g.CreateShader(type);
  const char* text = src.c_str();
  g.ShaderSource(s, 1, &text, nullptr);
  g.CompileShader(s);
  GLint ok = 0;
  g.GetShaderiv(s, GL_COMPILE_STATUS, &ok);
  if (!ok) {
    const std::string log = info_log(s, g.GetShaderiv, g.GetShaderInfoLog);
    g.DeleteShader(s);
    throw std::runtime_error("shader " + path + " does not compile: " + log);
  }
  return s;
}

}  // namespace

ShaderProgram::ShaderProgram(const std::string& vertex_path, const std::string& fragment_path,
                             const std::vector<std::string>& defines) {
  const Api& g = api();
  const GLuint vs = compile(GL_VERTEX_SHADER, vertex_path, defines);
  GLuint fs = 0;
  try {
    fs = compile(GL_FRAGMENT_SHADER, fragment_path, defines);
  } catch (...) {
    g.DeleteShader(vs);
    throw;
  }
  program_ = g.CreateProgram();
  g.AttachShader(program_, vs);
  g.AttachShader(program_, fs);
  g.LinkProgram(program_);
  g.DeleteShader(vs);
  g.DeleteShader(fs);
  GLint ok = 0;
  g.GetProgramiv(program_, GL_LINK_STATUS, &ok);
  if (!ok) {
    const std::string log = info_log(program_, g.GetProgramiv, g.GetProgramInfoLog);
    g.DeleteProgram(program_);
    throw std::runtime_error("shaders " + vertex_path + " + " + fragment_path + " do not link: " + log);
  }
}

ShaderProgram::~ShaderProgram() {
  if (program_ && api().DeleteProgram) api().DeleteProgram(program_);
}

void ShaderProgram::use() const { api().UseProgram(program_); }

GLint ShaderProgram::uniform(const char* name) const { return api().GetUniformLocation(program_, name); }

}  // namespace pneumo::gl
