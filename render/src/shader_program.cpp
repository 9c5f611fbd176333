#include "arbci/render/shader_program.h"

#include <string_view>
#include <vector>

#include "arbci/assets.h"
#include "arbci/render/gl_context.h"
#include "gl.h"

namespace arbci::render {
namespace {

GLuint compile(GLenum type, std::string_view source, const std::string& name) {
  GLuint shader = glCreateShader(type);
  const char* text = source.data();
  const GLint length = static_cast<GLint>(source.size());
  glShaderSource(shader, 1, &text, &length);
  glCompileShader(shader);
  GLint ok = GL_FALSE;
  glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
  if (!ok) {
    GLint log_length = 0;
    glGetShaderiv(shader, GL_INFO_LOG_LENGTH, &log_length);
    std::vector<char> log(static_cast<size_t>(log_length) + 1, '\0');
    glGetShaderInfoLog(shader, log_length, nullptr, log.data());
    glDeleteShader(shader);
    throw GlError("shader '" + name + (type == GL_VERTEX_SHADER ? ".vert" : ".frag") +
                  "' does not compile: " + log.data());
  }
  return shader;
}

}  // namespace

ShaderProgram::ShaderProgram(std::string_view vertex_source, std::string_view fragment_source,
                             const std::string& name) {
  const GLuint vertex = compile(GL_VERTEX_SHADER, vertex_source, name);
  GLuint fragment = 0;
  try {
    fragment = compile(GL_FRAGMENT_SHADER, fragment_source, name);
  } catch (...) {
    glDeleteShader(vertex);
    throw;
  }
  program_ = glCreateProgram();
  glAttachShader(program_, vertex);
  glAttachShader(program_, fragment);
  glLinkProgram(program_);
  glDeleteShader(vertex);
  glDeleteShader(fragment);
  GLint ok = GL_FALSE;
  glGetProgramiv(program_, GL_LINK_STATUS, &ok);
  if (!ok) {
    char log[1024] = {};
    glGetProgramInfoLog(program_, sizeof log, nullptr, log);
    glDeleteProgram(program_);
    throw GlError("shader program '" + name + "' does not link: " + log);
  }
}

ShaderProgram ShaderProgram::fromAssets(const std::string& name) {
  return ShaderProgram(assets::embedded("shaders/" + name + ".vert"),
                       assets::embedded("shaders/" + name + ".frag"), name);
}

ShaderProgram::~ShaderProgram() {
  if (program_) glDeleteProgram(program_);
}

ShaderProgram::ShaderProgram(ShaderProgram&& other) noexcept : program_(other.program_) {
  other.program_ = 0;
}

void ShaderProgram::use() const {
  glUseProgram(program_);
}

int ShaderProgram::uniform(const char* name) const {
  return glGetUniformLocation(program_, name);
}

}  // namespace arbci::render
