#pragma once
// A linked GLSL program from embedded sources, with feature variants by prepended #defines
// (inserted after the #version line). Compile and link errors throw with the driver's log.
#include <string>
#include <vector>

#include "render/gl_api.h"

namespace pneumo::gl {

class ShaderProgram {
 public:
  ShaderProgram(const std::string& vertex_path, const std::string& fragment_path,
                const std::vector<std::string>& defines = {});
  ~ShaderProgram();
  ShaderProgram(const ShaderProgram&) = delete;
  ShaderProgram& operator=(const ShaderProgram&) = delete;

  GLuint id() const { return program_; }
  void use() const;
  /// Uniform location; -1 (ignored by glUniform*) when the compiler removed an unused one.
  GLint uniform(const char* name) const;

 private:
  GLuint program_ = 0;
};

}  // namespace pneumo::gl
