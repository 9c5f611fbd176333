// A linked GLSL program owned RAII-style; compile and link errors throw GlError with the log.
#pragma once

#include <string>
#include <string_view>

namespace arbci::render {

class ShaderProgram {
 public:
  ShaderProgram(std::string_view vertex_source, std::string_view fragment_source,
                const std::string& name);
  // Builds from the embedded assets "shaders/<name>.vert" and "shaders/<name>.frag".
  static ShaderProgram fromAssets(const std::string& name);
  ~ShaderProgram();
  ShaderProgram(ShaderProgram&& other) noexcept;
  ShaderProgram& operator=(ShaderProgram&&) = delete;
  ShaderProgram(const ShaderProgram&) = delete;
  ShaderProgram& operator=(const ShaderProgram&) = delete;

  void use() const;
  int uniform(const char* name) const;
  unsigned int id() const { return program_; }

 private:
  unsigned int program_ = 0;
};

}  // namespace arbci::render
